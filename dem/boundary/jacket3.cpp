// The jacket of the 3D model: a confining pressure on the lateral faces, as a membrane applies it. See
// components3.hpp.
//
// Each lateral face carries the follower force F = -p A n, A n its area times its outward normal turned with its
// block, at its centroid turned with its block (the face is a face of a rigid block: its area does not change);
// the work p does is booked. A face carries pressure while its block still has an intact bond: a block that lost
// them all is a fragment the membrane spans rather than pushes back (faces_lost counts those faces, as in 2D).
#include <algorithm>
#include <stdexcept>

#include "dem/boundary/components3.hpp"

namespace rbdem {

JacketImpl<3>::JacketImpl(const Model<3>& m, double pressure) : pressure_(pressure) {
  for (std::size_t k = 0; k < m.surface.size(); ++k)
    if (m.surface[k].tag == FaceTag::lateral) faces_.push_back(k);
}

std::vector<std::pair<std::string, double>> JacketImpl<3>::readings() const {
  return {{"pressure_pa", pressure_}, {"work_j", work_}, {"faces_lost", double(lost_)},
          {"faces_lost_max", double(lost_max_)}};
}

std::pair<Vec3, Vec3> JacketImpl<3>::face_force(const Model<3>& m, std::size_t k, Quat q) const {
  const SurfaceFace& f = m.surface[k];
  return {(-pressure_ * f.area) * rotate(q, f.normal), rotate(q, f.r)};
}

double JacketImpl<3>::add_forces(const Model<3>& m, const ModelState<3>& s, std::vector<Vec3>& force,
                                 std::vector<Vec3>& moment, double dt, bool advance) {
  if (!(pressure_ > 0.0)) {
    if (advance) lost_ = 0;
    return 0.0;
  }
  int lost = 0;
  double work = 0.0;
  for (std::size_t k : faces_) {
    const std::size_t b = std::size_t(m.surface[k].block);
    if (!m.has_intact_bond(int(b), s.broken)) {
      ++lost;
      continue;
    }
    const auto [f, r] = face_force(m, k, s.rotation(b));
    force[b] += f, moment[b] += cross(r, f);
    work += dot(f, s.velocity(b) + cross(s.spin(b), r));
  }
  if (advance) lost_ = lost, lost_max_ = std::max(lost_max_, lost), work_ += work * dt;
  return 0.0;
}

void JacketImpl<3>::loads(const Model<3>& m, const ModelState<3>& s, int component, BoundaryLoads& out) const {
  if (!(pressure_ > 0.0)) return;
  for (std::size_t k : faces_) {
    const std::size_t b = std::size_t(m.surface[k].block);
    if (!m.has_intact_bond(int(b), s.broken)) continue;
    const auto [f, r] = face_force(m, k, s.rotation(b));
    const Vec3 p = s.position(b) + r;
    out.block.push_back(int(b)), out.component.push_back(component);
    out.point.insert(out.point.end(), {p.x, p.y, p.z});
    out.force.insert(out.force.end(), {f.x, f.y, f.z});
    out.moment.insert(out.moment.end(), {0.0, 0.0, 0.0});
  }
}

std::vector<double> JacketImpl<3>::reference_load(const Model<3>& m, double p) const {
  std::vector<double> load(6 * m.num_blocks(), 0.0);
  for (std::size_t k : faces_) {
    const SurfaceFace& f = m.surface[k];
    const Vec3 F = (-p * f.area) * f.normal, M = cross(f.r, F);
    double* l = &load[6 * std::size_t(f.block)];
    l[0] += F.x, l[1] += F.y, l[2] += F.z, l[3] += M.x, l[4] += M.y, l[5] += M.z;
  }
  return load;
}

void JacketImpl<3>::save(Snapshot& s) const {
  s.add("jacket/pressure", Extent::scalar, pressure_);
  s.add("jacket/work", Extent::scalar, work_);
  s.add("jacket/lost", Extent::scalar, lost_);
  s.add("jacket/lost_max", Extent::scalar, lost_max_);
}

void JacketImpl<3>::load(const Snapshot& s, const Model<3>&) {
  pressure_ = s.get<double>("jacket/pressure");
  work_ = s.get<double>("jacket/work");
  lost_ = s.get<int>("jacket/lost");
  lost_max_ = s.get<int>("jacket/lost_max");
}

}  // namespace rbdem
