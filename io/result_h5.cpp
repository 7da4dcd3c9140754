// result.h5 and result.xdmf of a run, and the reader. See result_h5.hpp; the layout is in docs/outputs.md. The
// curve, the crack log and the frames' scalars are written by walking their records' field tables
// (dem/records.hpp, io/record_h5.hpp).
#include "io/result_h5.hpp"

#include <hdf5.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <mutex>
#include <stdexcept>
#include <type_traits>
#include <utility>

#include <fmt/format.h>

#include "io/h5.hpp"
#include "io/record_h5.hpp"
#include "io/results.hpp"

namespace rbdem::io {

using namespace h5;

namespace {

std::string frame_name(std::size_t k) { return fmt::format("{:05d}", k); }

std::string xml_escape(const std::string& s) {
  std::string r;
  for (const char c : s) {
    switch (c) {
      case '&': r += "&amp;"; break;
      case '<': r += "&lt;"; break;
      case '>': r += "&gt;"; break;
      case '"': r += "&quot;"; break;
      case '\'': r += "&apos;"; break;
      default: r += c;
    }
  }
  return r;
}

void check_consistent(const Specimen& sp, const TestResult& r) {
  const std::size_t nb = sp.num_blocks();
  const std::size_t verts = std::size_t(block_vertices(sp.dim));
  if (sp.cells.size() != verts * nb || sp.blocks.centroid.size() != std::size_t(sp.dim) * nb)
    throw std::invalid_argument(fmt::format("write_result_h5: the specimen has {} blocks but {} cell vertices and {} "
                                            "centroid components: pass the specimen of the simulation that ran",
                                            nb, sp.cells.size(), sp.blocks.centroid.size()));
  for (const auto& f : r.frames)
    if (f.blocks() != nb || f.dim != sp.dim || f.cracks > r.cracks.size())
      throw std::invalid_argument(fmt::format("write_result_h5: frame at step {} has {} blocks and {} cracks, the "
                                              "specimen {} blocks and the log {} cracks",
                                              f.step, f.blocks(), f.cracks, nb, r.cracks.size()));
  for (const auto& f : r.frames) {
    const ForceNetwork& n = f.network;
    const bool sized = n.j.size() == n.size() && n.kind.size() == n.size() && n.normal_force.size() == n.size() &&
                       n.force.size() == std::size_t(sp.dim) * n.size();
    const auto outside = [nb](std::int32_t b) { return b < 0 || std::size_t(b) >= nb; };
    if (!sized || std::any_of(n.i.begin(), n.i.end(), outside) || std::any_of(n.j.begin(), n.j.end(), outside))
      throw std::invalid_argument(fmt::format("write_result_h5: the force network of the frame at step {} does not "
                                              "belong to the specimen of {} blocks",
                                              f.step, nb));
  }
  for (const auto& c : r.cracks)
    if (c.bond < 0 || std::size_t(c.bond) >= sp.num_bonds())
      throw std::invalid_argument(fmt::format("write_result_h5: crack on bond {} but the specimen has {} bonds",
                                              c.bond, sp.num_bonds()));
}

// /mesh: the nodes, the cells, the layers, the disconnected cells ParaView draws, the centroids.
void write_mesh(const Writer& w, hid_t file, const Specimen& sp) {
  const Id g = w.group(file, "mesh");
  const std::size_t nb = sp.num_blocks(), dim = std::size_t(sp.dim), verts = std::size_t(block_vertices(sp.dim));
  w.dataset(g, "nodes", sp.nodes, dim);
  std::vector<std::int32_t> conn(verts * nb), layer(sp.blocks.layer.begin(), sp.blocks.layer.end());
  for (std::size_t k = 0; k < conn.size(); ++k) conn[k] = std::int32_t(k);
  w.dataset(g, sp.dim == 2 ? "triangles" : "tetrahedra", sp.cells, verts);
  w.dataset(g, "layer", layer);
  w.dataset(g, "block_connectivity", conn, verts);
  w.dataset(g, "centroid", sp.blocks.centroid, dim);
  if (!sp.layer_names.empty()) w.attribute_strings(g, "layer_names", sp.layer_names);
}

// /bonds, with the breakage record from the crack log.
void write_bonds(const Writer& w, hid_t file, const Specimen& sp, const std::vector<Crack>& cracks) {
  const auto& B = sp.bonds;
  const std::size_t nb = sp.num_bonds();
  const Id g = w.group(file, "bonds");
  std::vector<std::int32_t> kind(nb), mode(nb);  // mode 0: intact
  std::vector<double> t_break(nb, std::numeric_limits<double>::quiet_NaN()), e_break = t_break;
  for (std::size_t b = 0; b < nb; ++b) kind[b] = std::int32_t(B.kind[b]);
  for (const auto& c : cracks) {
    const auto b = std::size_t(c.bond);
    t_break[b] = c.time, e_break[b] = c.strain, mode[b] = std::int32_t(c.mode);
  }
  w.dataset(g, "i", B.i), w.dataset(g, "j", B.j);
  if (sp.dim == 2) {  // the edge's two nodes
    std::vector<std::int32_t> a(nb), b(nb);
    for (std::size_t k = 0; k < nb; ++k) a[k] = B.nodes[2 * k], b[k] = B.nodes[2 * k + 1];
    w.dataset(g, "node_a", a), w.dataset(g, "node_b", b);
  } else {
    w.dataset(g, "nodes", B.nodes, std::size_t(sp.dim));
  }
  w.dataset(g, "kind", kind), w.dataset(g, sp.dim == 2 ? "length" : "area", B.size);
  w.dataset(g, "midpoint", B.midpoint, std::size_t(sp.dim));
  w.dataset(g, "break_time", t_break), w.dataset(g, "break_strain", e_break), w.dataset(g, "break_mode", mode);
}

// /frames/NNNNN/network: the force network of the frame as lines between the block centroids (forces.xdmf draws
// them): the centroids (T x 3, float, z = 0 in 2D), the two blocks of each link (L x 2), its kind (0 bond,
// 1 contact, uint8), its force on the second block (L x 3, float) and its normal force (L, float, tension positive).
void write_network(const Writer& w, hid_t frame, const Specimen& sp, const Frame& f) {
  const ForceNetwork& n = f.network;
  const std::size_t nb = sp.num_blocks(), d = std::size_t(sp.dim), links = n.size();
  std::vector<float> centroid(3 * nb, 0.0f), force(3 * links, 0.0f);
  for (std::size_t a = 0; a < d; ++a)
    for (std::size_t b = 0; b < nb; ++b) centroid[3 * b + a] = float(f.component(int(a))[b]);
  std::vector<std::int32_t> blocks(2 * links);
  for (std::size_t k = 0; k < links; ++k) {
    blocks[2 * k] = n.i[k], blocks[2 * k + 1] = n.j[k];
    for (std::size_t a = 0; a < d; ++a) force[3 * k + a] = n.force[d * k + a];
  }
  const Id g = w.group(frame, "network");
  w.dataset(g, "centroid", centroid, 3);
  w.dataset(g, "blocks", blocks, 2);
  w.dataset(g, "kind", n.kind);
  w.dataset(g, "force", force, 3);
  w.dataset(g, "normal_force", n.normal_force);
}

ForceNetwork read_network(const Reader& rd, hid_t frame, int dim) {
  const Id g = rd.group(frame, "network");
  ForceNetwork n;
  const auto blocks = rd.dataset<std::int32_t>(g, "blocks");
  const auto force = rd.dataset<float>(g, "force");
  n.kind = rd.dataset<std::uint8_t>(g, "kind");
  n.normal_force = rd.dataset<float>(g, "normal_force");
  for (std::size_t k = 0; k < n.kind.size(); ++k) {
    n.i.push_back(blocks[2 * k]), n.j.push_back(blocks[2 * k + 1]);
    for (int a = 0; a < dim; ++a) n.force.push_back(force[3 * k + std::size_t(a)]);
  }
  return n;
}

// 3D: each block's rotation from its reference orientation as one number, the angle of its unit quaternion
// (qw, qx, qy, qz): 2 atan2(|(qx, qy, qz)|, |qw|), rad in [0, pi], about whatever axis (ParaView colours by it as
// it colours a 2D run by theta; the axis is in the pose's quaternion).
std::vector<double> rotation_angles(const Frame& f) {
  const std::size_t nb = f.blocks();
  const double *qw = f.component(3), *qx = f.component(4), *qy = f.component(5), *qz = f.component(6);
  std::vector<double> angle(nb);
  for (std::size_t b = 0; b < nb; ++b)
    angle[b] = 2.0 * std::atan2(std::sqrt(qx[b] * qx[b] + qy[b] * qy[b] + qz[b] * qz[b]), std::abs(qw[b]));
  return angle;
}

// /frames/NNNNN: the poses by component (in double: the exact state), the cells' vertices for display, the
// damage count per block, and the frame's scalars.
void write_frames(const Writer& w, hid_t file, const Specimen& sp, const TestResult& r) {
  const Id g = w.group(file, "frames");
  w.attribute(g, "count", std::int64_t(r.frames.size()));
  const std::size_t nb = sp.num_blocks(), dim = std::size_t(sp.dim), verts = std::size_t(block_vertices(sp.dim));
  const int components = pose_size(sp.dim);
  std::vector<std::int32_t> damage(nb, 0);
  std::size_t counted = 0;  // cracks already in `damage`
  // Vertices are for display (ParaView, figures): single precision resolves 10 nm on a 10 cm specimen and halves
  // the file; the exact state is the pose in double.
  std::vector<float> vertices(3 * verts * nb, 0.0f);
  std::vector<double> pose(static_cast<std::size_t>(components)), at(dim);
  for (std::size_t k = 0; k < r.frames.size(); ++k) {
    const Frame& f = r.frames[k];
    if (f.cracks < counted) std::fill(damage.begin(), damage.end(), 0), counted = 0;
    for (; counted < f.cracks; ++counted) {
      const auto b = std::size_t(r.cracks[counted].bond);
      ++damage[std::size_t(sp.bonds.i[b])], ++damage[std::size_t(sp.bonds.j[b])];
    }
    // Rigid blocks: vertex v of block t is the block's pose applied to its shape vertex, in the order of its cell.
    for (std::size_t t = 0; t < nb; ++t) {
      for (int c = 0; c < components; ++c) pose[std::size_t(c)] = f.component(c)[t];
      for (std::size_t v = 0; v < verts; ++v) {
        place(sp.dim, pose.data(), &sp.blocks.shape[(t * verts + v) * dim], at.data());
        for (std::size_t d = 0; d < dim; ++d) vertices[3 * (verts * t + v) + d] = float(at[d]);
      }
    }
    const Id fg = w.group(g, frame_name(k));
    for (int c = 0; c < components; ++c)
      w.dataset(fg, pose_name(sp.dim, c), std::vector<double>(f.component(c), f.component(c) + nb));
    w.dataset(fg, "vertices", vertices, 3);
    if (sp.dim == 3) w.dataset(fg, "rotation_angle", rotation_angles(f));
    w.dataset(fg, "damage", damage);
    write_network(w, fg, sp, f);
    write_attributes(w, fg, sp.dim, f);
  }
}

void write_h5_file(const std::string& tmp, const Scene& scene, const Specimen& sp, const TestResult& r,
                   int threads) {
  const Writer w(tmp, threads);
  {
    Id file = w.create_file();
    {  // /scene
      const Id g = w.group(file, "scene");
      w.attribute(g, "toml", to_toml(scene));
      w.attribute(g, "json", scene_json(scene).dump(2));
    }
    write_mesh(w, file, sp);
    write_bonds(w, file, sp, r.cracks);
    write_table(w, w.group(file, "history"), sp.dim, r.curve);
    write_table(w, w.group(file, "cracks"), sp.dim, r.cracks);  // the crack log in order
    write_frames(w, file, sp, r);
    w.attribute(w.group(file, "summary"), "json", run_summary(scene, r).dump(2));
    w.save(file);
  }  // the file is closed here, before the caller renames it
}

}  // namespace

void write_result_h5(const std::filesystem::path& path, const Scene& scene, const Specimen& specimen,
                     const TestResult& r, int threads) {
  check_consistent(specimen, r);
  const std::lock_guard<std::mutex> lock(h5::lock());
  const std::string tmp = path.string() + ".tmp";
  try {
    write_h5_file(tmp, scene, specimen, r, threads);
  } catch (...) {
    std::error_code ec;
    std::filesystem::remove(tmp, ec);  // never leave a half file behind
    throw;
  }
  std::filesystem::rename(tmp, path);
}

namespace {

// The h5 file relative to the XDMF file (escaped for XML), so the run folder can be moved as a whole.
std::string h5_reference(const std::filesystem::path& xdmf_path, const std::filesystem::path& h5_path) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::absolute(xdmf_path).parent_path();
  fs::path h5 = fs::absolute(h5_path).lexically_normal().lexically_relative(dir.lexically_normal());
  if (h5.empty()) h5 = fs::absolute(h5_path);
  return xml_escape(h5.generic_string());
}

}  // namespace

void write_result_xdmf(const std::filesystem::path& xdmf_path, const std::filesystem::path& h5_path,
                       const Specimen& specimen, const std::string& test, const std::vector<Frame>& frames) {
  const std::string ref = h5_reference(xdmf_path, h5_path);
  const std::size_t T = specimen.num_blocks(), verts = std::size_t(block_vertices(specimen.dim));
  const char* cell = cell_type(specimen.dim);

  std::string s = fmt::format(
      "<?xml version=\"1.0\" ?>\n"
      "<!DOCTYPE Xdmf SYSTEM \"Xdmf.dtd\" []>\n"
      "<!-- rbdem {} run: one rigid block per cell, drawn disconnected ({} vertices per block) so cracks open.\n"
      "     Open this file in ParaView (Xdmf3 reader); the time is the run's time in s. -->\n"
      "<Xdmf Version=\"3.0\">\n"
      "  <Domain>\n"
      "    <Grid Name=\"{}\" GridType=\"Collection\" CollectionType=\"Temporal\">\n",
      xml_escape(test), verts, xml_escape(test));
  for (std::size_t k = 0; k < frames.size(); ++k) {
    const Frame& f = frames[k];
    const std::string fr = "/frames/" + frame_name(k);
    s += fmt::format("      <Grid Name=\"frame_{}\" GridType=\"Uniform\">\n", frame_name(k));
    s += fmt::format("        <Time Value=\"{:.17g}\"/>\n", f.time);
    s += fmt::format(
        "        <Information Name=\"frame\" Value=\"step {} strain {:.6g} stress_pa {:.6g} label {} cracks {}\"/>\n",
        f.step, f.strain, f.stress, xml_escape(f.label.empty() ? "-" : f.label), f.cracks);
    s += fmt::format("        <Topology TopologyType=\"{}\" NumberOfElements=\"{}\">\n", cell, T);
    s += fmt::format("          <DataItem Dimensions=\"{} {}\" NumberType=\"Int\" Precision=\"4\" Format=\"HDF\">"
                     "{}:/mesh/block_connectivity</DataItem>\n",
                     T, verts, ref);
    s += "        </Topology>\n";
    s += "        <Geometry GeometryType=\"XYZ\">\n";
    s += fmt::format("          <DataItem Dimensions=\"{} 3\" NumberType=\"Float\" Precision=\"4\" Format=\"HDF\">"
                     "{}:{}/vertices</DataItem>\n",
                     verts * T, ref, fr);
    s += "        </Geometry>\n";
    auto attribute = [&](const char* name, const char* type, int precision, const std::string& dataset) {
      s += fmt::format("        <Attribute Name=\"{}\" AttributeType=\"Scalar\" Center=\"Cell\">\n", name);
      s += fmt::format("          <DataItem Dimensions=\"{}\" NumberType=\"{}\" Precision=\"{}\" Format=\"HDF\">"
                       "{}:{}</DataItem>\n",
                       T, type, precision, ref, dataset);
      s += "        </Attribute>\n";
    };
    attribute("layer", "Int", 4, "/mesh/layer");
    attribute("damage", "Int", 4, fr + "/damage");
    attribute("rotation", "Float", 8, fr + (specimen.dim == 2 ? "/theta" : "/rotation_angle"));
    s += "      </Grid>\n";
  }
  s += "    </Grid>\n  </Domain>\n</Xdmf>\n";
  write_text_atomic(xdmf_path, s);
}

void write_network_xdmf(const std::filesystem::path& xdmf_path, const std::filesystem::path& h5_path,
                        const Specimen& specimen, const std::string& test, const std::vector<Frame>& frames) {
  const std::string ref = h5_reference(xdmf_path, h5_path);
  const std::size_t T = specimen.num_blocks();
  std::string s = fmt::format(
      "<?xml version=\"1.0\" ?>\n"
      "<!DOCTYPE Xdmf SYSTEM \"Xdmf.dtd\" []>\n"
      "<!-- rbdem {} run: the force network, one line per intact bond and per contact between the centroids of its\n"
      "     two blocks. Open this file in ParaView (Xdmf3 reader); the time is the run's time in s. -->\n"
      "<Xdmf Version=\"3.0\">\n"
      "  <Domain>\n"
      "    <Grid Name=\"{}_forces\" GridType=\"Collection\" CollectionType=\"Temporal\">\n",
      xml_escape(test), xml_escape(test));
  for (std::size_t k = 0; k < frames.size(); ++k) {
    const Frame& f = frames[k];
    const std::string fr = "/frames/" + frame_name(k) + "/network";
    const std::size_t L = f.network.size();
    s += fmt::format("      <Grid Name=\"forces_{}\" GridType=\"Uniform\">\n", frame_name(k));
    s += fmt::format("        <Time Value=\"{:.17g}\"/>\n", f.time);
    s += fmt::format("        <Topology TopologyType=\"Polyline\" NodesPerElement=\"2\" NumberOfElements=\"{}\">\n", L);
    s += fmt::format("          <DataItem Dimensions=\"{} 2\" NumberType=\"Int\" Precision=\"4\" Format=\"HDF\">"
                     "{}:{}/blocks</DataItem>\n",
                     L, ref, fr);
    s += "        </Topology>\n";
    s += "        <Geometry GeometryType=\"XYZ\">\n";
    s += fmt::format("          <DataItem Dimensions=\"{} 3\" NumberType=\"Float\" Precision=\"4\" Format=\"HDF\">"
                     "{}:{}/centroid</DataItem>\n",
                     T, ref, fr);
    s += "        </Geometry>\n";
    auto attribute = [&](const char* name, const char* type, const char* number, int precision,
                         const std::string& dims) {
      s += fmt::format("        <Attribute Name=\"{}\" AttributeType=\"{}\" Center=\"Cell\">\n", name, type);
      s += fmt::format("          <DataItem Dimensions=\"{}\" NumberType=\"{}\" Precision=\"{}\" Format=\"HDF\">"
                       "{}:{}/{}</DataItem>\n",
                       dims, number, precision, ref, fr, name);
      s += "        </Attribute>\n";
    };
    attribute("normal_force", "Scalar", "Float", 4, std::to_string(L));
    attribute("force", "Vector", "Float", 4, fmt::format("{} 3", L));
    attribute("kind", "Scalar", "UChar", 1, std::to_string(L));
    s += "      </Grid>\n";
  }
  s += "    </Grid>\n  </Domain>\n</Xdmf>\n";
  write_text_atomic(xdmf_path, s);
}

StoredRun read_result_h5(const std::filesystem::path& path, bool with_positions) {
  const std::lock_guard<std::mutex> lock(h5::lock());
  const Reader rd(path.string());
  const Id file = rd.open_file();
  StoredRun out;
  {
    const Id g = rd.group(file, "scene");
    out.scene_toml = rd.attribute_string(g, "toml");
    out.scene_json = rd.attribute_string(g, "json");
  }
  out.summary_json = rd.attribute_string(rd.group(file, "summary"), "json");
  {
    const Id g = rd.group(file, "mesh");
    std::vector<hsize_t> dims;
    out.nodes = rd.dataset<double>(g, "nodes", &dims);
    out.dim = dims.size() == 2 ? int(dims[1]) : 2;
    out.cells = rd.dataset<std::int32_t>(g, out.dim == 2 ? "triangles" : "tetrahedra");
    out.layer = rd.dataset<std::int32_t>(g, "layer");
    if (H5Aexists(g, "layer_names") > 0) out.layer_names = rd.attribute_strings(g, "layer_names");
  }
  out.curve = read_table<CurvePoint>(rd, rd.group(file, "history"), out.dim, path.string());
  out.cracks = read_table<Crack>(rd, rd.group(file, "cracks"), out.dim, path.string());
  {
    const Id g = rd.group(file, "frames");
    const auto count = rd.attribute<std::int64_t>(g, "count");
    out.frames.resize(std::size_t(std::max<std::int64_t>(count, 0)));
    for (std::size_t k = 0; k < out.frames.size(); ++k) {
      const Id fg = rd.group(g, frame_name(k));
      Frame& f = out.frames[k];
      f.dim = out.dim;
      read_attributes(rd, fg, out.dim, f);
      if (!with_positions) continue;
      for (int c = 0; c < pose_size(out.dim); ++c) {
        const auto v = rd.dataset<double>(fg, pose_name(out.dim, c));
        f.pose.insert(f.pose.end(), v.begin(), v.end());
      }
      f.network = read_network(rd, fg, out.dim);
    }
  }
  return out;
}

std::optional<std::vector<std::uint64_t>> h5_dataset_shape(const std::filesystem::path& path,
                                                           const std::string& dataset) {
  const std::lock_guard<std::mutex> lock(h5::lock());
  const QuietHdf5Errors quiet;
  if (H5Fis_hdf5(path.string().c_str()) <= 0) return std::nullopt;
  const Id file(H5Fopen(path.string().c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose);
  if (file < 0) return std::nullopt;
  // Walk the path one link at a time: H5Lexists on "/a/b/c" fails when /a/b is missing.
  std::string prefix;
  std::size_t pos = 0;
  while (pos < dataset.size()) {
    const std::size_t next = dataset.find('/', pos + 1);
    prefix = dataset.substr(0, next);
    if (!prefix.empty() && prefix != "/" && H5Lexists(file, prefix.c_str(), H5P_DEFAULT) <= 0) return std::nullopt;
    if (next == std::string::npos) break;
    pos = next;
  }
  const Id ds(H5Oopen(file, dataset.c_str(), H5P_DEFAULT), H5Oclose);
  if (ds < 0 || H5Iget_type(ds) != H5I_DATASET) return std::nullopt;
  const Id space(H5Dget_space(ds), H5Sclose);
  const int rank = H5Sget_simple_extent_ndims(space);
  if (rank < 0) return std::nullopt;
  std::vector<hsize_t> dims(std::size_t(rank), 0);
  H5Sget_simple_extent_dims(space, dims.data(), nullptr);
  return std::vector<std::uint64_t>(dims.begin(), dims.end());
}

}  // namespace rbdem::io
