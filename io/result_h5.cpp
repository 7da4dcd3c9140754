// result.h5 and result.xdmf of a UCS run, and the reader. See result_h5.hpp; the layout is in docs/outputs.md.
#include "io/result_h5.hpp"

#include <hdf5.h>

#include <algorithm>
#include <array>
#include <cstring>
#include <cmath>
#include <limits>
#include <mutex>
#include <stdexcept>
#include <type_traits>
#include <utility>

#include <fmt/format.h>

#include "io/h5.hpp"
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

void check_consistent(const TriMesh& mesh, const Topology& topo, const TestResult& r) {
  const std::size_t nt = mesh.triangles.size();
  if (topo.blocks.size() != nt || mesh.layer.size() != nt)
    throw std::invalid_argument(fmt::format("write_result_h5: the topology has {} blocks but the mesh {} triangles "
                                            "({} layer ids): pass the mesh the topology was built from",
                                            topo.blocks.size(), nt, mesh.layer.size()));
  for (const auto& f : r.frames)
    if (f.x.size() != nt || f.y.size() != nt || f.theta.size() != nt || f.cracks > r.cracks.size())
      throw std::invalid_argument(fmt::format("write_result_h5: frame at step {} has {} blocks and {} cracks, the "
                                              "mesh {} blocks and the log {} cracks",
                                              f.step, f.x.size(), f.cracks, nt, r.cracks.size()));
  for (const auto& c : r.cracks)
    if (c.bond < 0 || std::size_t(c.bond) >= topo.bonds.size())
      throw std::invalid_argument(fmt::format("write_result_h5: crack on bond {} but the topology has {} bonds",
                                              c.bond, topo.bonds.size()));
}

}  // namespace

// -------------------------------------------------------------------------------------------------------------------

namespace {

void write_h5_file(const std::string& tmp, const Scene& scene, const TriMesh& mesh, const Topology& topo,
                   const TestResult& r, int threads) {
  const Writer w(tmp, threads);
  const std::size_t nt = mesh.triangles.size(), nb = topo.bonds.size();
  {
    Id file = w.create_file();

    {  // /scene
      const Id g = w.group(file, "scene");
      w.attribute(g, "toml", to_toml(scene));
      w.attribute(g, "json", scene_json(scene).dump(2));
    }

    {  // /mesh
      const Id g = w.group(file, "mesh");
      std::vector<double> nodes;
      nodes.reserve(2 * mesh.nodes.size());
      for (const auto& p : mesh.nodes) nodes.insert(nodes.end(), {p[0], p[1]});
      w.dataset(g, "nodes", nodes, 2);
      std::vector<std::int32_t> tri, conn, layer(mesh.layer.begin(), mesh.layer.end());
      tri.reserve(3 * nt), conn.reserve(3 * nt);
      for (std::size_t t = 0; t < nt; ++t)
        for (int k = 0; k < 3; ++k) {
          tri.push_back(mesh.triangles[t][std::size_t(k)]);
          conn.push_back(std::int32_t(3 * t + std::size_t(k)));
        }
      w.dataset(g, "triangles", tri, 3);
      w.dataset(g, "layer", layer);
      w.dataset(g, "block_connectivity", conn, 3);
      std::vector<double> centroid;
      centroid.reserve(2 * nt);
      for (std::size_t t = 0; t < nt; ++t) centroid.insert(centroid.end(), {topo.blocks.cx[t], topo.blocks.cy[t]});
      w.dataset(g, "centroid", centroid, 2);
      if (!mesh.layer_names.empty()) w.attribute_strings(g, "layer_names", mesh.layer_names);
    }

    {  // /bonds, with the breakage record from the crack log
      const auto& B = topo.bonds;
      const Id g = w.group(file, "bonds");
      std::vector<std::int32_t> kind(nb), mode(nb);  // mode 0: intact
      std::vector<double> mid, t_break(nb, std::numeric_limits<double>::quiet_NaN()), e_break = t_break;
      mid.reserve(2 * nb);
      for (std::size_t b = 0; b < nb; ++b) {
        kind[b] = std::int32_t(B.kind[b]);
        mid.insert(mid.end(), {B.mx[b], B.my[b]});
      }
      for (const auto& c : r.cracks) {
        const auto b = std::size_t(c.bond);
        t_break[b] = c.time, e_break[b] = c.strain, mode[b] = std::int32_t(c.mode);
      }
      w.dataset(g, "i", B.i), w.dataset(g, "j", B.j);
      w.dataset(g, "node_a", B.node_a), w.dataset(g, "node_b", B.node_b);
      w.dataset(g, "kind", kind), w.dataset(g, "length", B.length), w.dataset(g, "midpoint", mid, 2);
      w.dataset(g, "break_time", t_break), w.dataset(g, "break_strain", e_break), w.dataset(g, "break_mode", mode);
    }

    {  // /history: the curve, column by column
      const Id g = w.group(file, "history");
      const std::size_t n = r.curve.size();
      std::vector<std::int64_t> step(n);
      std::vector<double> time(n), strain(n), st(n), sb(n), ek(n), es(n), lat(n), vol(n);
      std::array<std::vector<std::int32_t>, 4> broken;
      for (auto& v : broken) v.resize(n);
      for (std::size_t k = 0; k < n; ++k) {
        const CurvePoint& p = r.curve[k];
        step[k] = p.step, time[k] = p.time, strain[k] = p.strain, st[k] = p.stress_top, sb[k] = p.stress_bottom;
        ek[k] = p.kinetic, es[k] = p.strain_energy, lat[k] = p.lateral_strain, vol[k] = volumetric_strain(p);
        for (std::size_t c = 0; c < 4; ++c) broken[c][k] = p.broken[c];
      }
      w.dataset(g, "step", step), w.dataset(g, "time_s", time), w.dataset(g, "strain", strain);
      w.dataset(g, "stress_top_pa", st), w.dataset(g, "stress_bottom_pa", sb);
      w.dataset(g, "kinetic_j", ek), w.dataset(g, "strain_energy_j", es), w.dataset(g, "lateral_strain", lat);
      w.dataset(g, "volumetric_strain", vol);
      w.dataset(g, "broken_rock_tensile", broken[0]), w.dataset(g, "broken_rock_shear", broken[1]);
      w.dataset(g, "broken_joint_tensile", broken[2]), w.dataset(g, "broken_joint_shear", broken[3]);
    }

    {  // /cracks: the crack log in order
      const Id g = w.group(file, "cracks");
      const std::size_t n = r.cracks.size();
      std::vector<double> time(n), strain(n), x(n), y(n), sigma(n), tau(n);
      std::vector<std::int32_t> kind(n), mode(n), bond(n);
      for (std::size_t k = 0; k < n; ++k) {
        const Crack& c = r.cracks[k];
        time[k] = c.time, strain[k] = c.strain, x[k] = c.x, y[k] = c.y, sigma[k] = c.sigma, tau[k] = c.tau;
        kind[k] = std::int32_t(c.kind), mode[k] = std::int32_t(c.mode), bond[k] = c.bond;
      }
      w.dataset(g, "time_s", time), w.dataset(g, "strain", strain), w.dataset(g, "x_m", x), w.dataset(g, "y_m", y);
      w.dataset(g, "kind", kind), w.dataset(g, "mode", mode), w.dataset(g, "bond", bond);
      w.dataset(g, "sigma_pa", sigma), w.dataset(g, "tau_pa", tau);
      w.dataset(g, "orientation_deg", crack_orientations_deg(r.cracks, topo));
    }

    {  // /frames/NNNNN
      const Id g = w.group(file, "frames");
      w.attribute(g, "count", std::int64_t(r.frames.size()));
      std::vector<std::int32_t> damage(nt, 0);
      std::size_t counted = 0;  // cracks already in `damage`
      // Vertices are for display (ParaView, figures): single precision resolves 10 nm on a 10 cm specimen and halves
      // the file; the exact state is x, y, theta in double.
      std::vector<float> vertices(9 * nt);
      for (std::size_t k = 0; k < r.frames.size(); ++k) {
        const Frame& f = r.frames[k];
        if (f.cracks < counted) std::fill(damage.begin(), damage.end(), 0), counted = 0;
        for (; counted < f.cracks; ++counted) {
          const auto b = std::size_t(r.cracks[counted].bond);
          ++damage[std::size_t(topo.bonds.i[b])], ++damage[std::size_t(topo.bonds.j[b])];
        }
        // Rigid blocks: vertex v of block t is (x, y) + R(theta) shape_v, in the order of mesh.triangles[t].
        for (std::size_t t = 0; t < nt; ++t) {
          const double c = std::cos(f.theta[t]), s = std::sin(f.theta[t]);
          const auto& sh = topo.blocks.shape[t];
          for (std::size_t v = 0; v < 3; ++v) {
            float* p = &vertices[9 * t + 3 * v];
            p[0] = float(f.x[t] + c * sh[2 * v] - s * sh[2 * v + 1]);
            p[1] = float(f.y[t] + s * sh[2 * v] + c * sh[2 * v + 1]);
            p[2] = 0.0f;
          }
        }
        const Id fg = w.group(g, frame_name(k));
        w.dataset(fg, "x", f.x), w.dataset(fg, "y", f.y), w.dataset(fg, "theta", f.theta);
        w.dataset(fg, "vertices", vertices, 3);
        w.dataset(fg, "damage", damage);
        w.attribute(fg, "step", std::int64_t(f.step));
        w.attribute(fg, "time", f.time), w.attribute(fg, "strain", f.strain), w.attribute(fg, "stress", f.stress);
        w.attribute(fg, "label", f.label);
        w.attribute(fg, "cracks", std::int64_t(f.cracks));
      }
    }

    {  // /summary
      const Id g = w.group(file, "summary");
      w.attribute(g, "json", run_summary(scene, r).dump(2));
    }
    w.save(file);
  }  // the file is closed here, before the caller renames it
}

}  // namespace

void write_result_h5(const std::filesystem::path& path, const Scene& scene, const TriMesh& mesh, const Topology& topo,
                     const TestResult& r, int threads) {
  check_consistent(mesh, topo, r);
  const std::lock_guard<std::mutex> lock(h5::lock());
  const std::string tmp = path.string() + ".tmp";
  try {
    write_h5_file(tmp, scene, mesh, topo, r, threads);
  } catch (...) {
    std::error_code ec;
    std::filesystem::remove(tmp, ec);  // never leave a half file behind
    throw;
  }
  std::filesystem::rename(tmp, path);
}

void write_result_xdmf(const std::filesystem::path& xdmf_path, const std::filesystem::path& h5_path,
                       std::size_t num_blocks, const std::vector<Frame>& frames) {
  namespace fs = std::filesystem;
  // Reference the h5 file relative to the XDMF file, so the run folder can be moved as a whole.
  const fs::path dir = fs::absolute(xdmf_path).parent_path();
  fs::path h5 = fs::absolute(h5_path).lexically_normal().lexically_relative(dir.lexically_normal());
  if (h5.empty()) h5 = fs::absolute(h5_path);
  const std::string ref = xml_escape(h5.generic_string());
  const std::size_t T = num_blocks;

  std::string s =
      "<?xml version=\"1.0\" ?>\n"
      "<!DOCTYPE Xdmf SYSTEM \"Xdmf.dtd\" []>\n"
      "<!-- rbdem UCS run: one rigid triangle per block, drawn disconnected (3 vertices per block) so cracks open.\n"
      "     Open this file in ParaView (Xdmf3 reader); the time is the run's time in s. -->\n"
      "<Xdmf Version=\"3.0\">\n"
      "  <Domain>\n"
      "    <Grid Name=\"ucs\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
  for (std::size_t k = 0; k < frames.size(); ++k) {
    const Frame& f = frames[k];
    const std::string fr = "/frames/" + frame_name(k);
    s += fmt::format("      <Grid Name=\"frame_{}\" GridType=\"Uniform\">\n", frame_name(k));
    s += fmt::format("        <Time Value=\"{:.17g}\"/>\n", f.time);
    s += fmt::format(
        "        <Information Name=\"frame\" Value=\"step {} strain {:.6g} stress_pa {:.6g} label {} cracks {}\"/>\n",
        f.step, f.strain, f.stress, xml_escape(f.label.empty() ? "-" : f.label), f.cracks);
    s += fmt::format("        <Topology TopologyType=\"Triangle\" NumberOfElements=\"{}\">\n", T);
    s += fmt::format("          <DataItem Dimensions=\"{} 3\" NumberType=\"Int\" Precision=\"4\" Format=\"HDF\">"
                     "{}:/mesh/block_connectivity</DataItem>\n",
                     T, ref);
    s += "        </Topology>\n";
    s += "        <Geometry GeometryType=\"XYZ\">\n";
    s += fmt::format("          <DataItem Dimensions=\"{} 3\" NumberType=\"Float\" Precision=\"4\" Format=\"HDF\">"
                     "{}:{}/vertices</DataItem>\n",
                     3 * T, ref, fr);
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
    attribute("rotation", "Float", 8, fr + "/theta");
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
    const auto nodes = rd.dataset<double>(g, "nodes");
    const auto tri = rd.dataset<std::int32_t>(g, "triangles");
    const auto layer = rd.dataset<std::int32_t>(g, "layer");
    for (std::size_t k = 0; k + 1 < nodes.size(); k += 2) out.mesh.nodes.push_back({nodes[k], nodes[k + 1]});
    for (std::size_t k = 0; k + 2 < tri.size(); k += 3) out.mesh.triangles.push_back({tri[k], tri[k + 1], tri[k + 2]});
    out.mesh.layer.assign(layer.begin(), layer.end());
    if (H5Aexists(g, "layer_names") > 0) out.mesh.layer_names = rd.attribute_strings(g, "layer_names");
  }

  {
    const Id g = rd.group(file, "history");
    const auto step = rd.dataset<std::int64_t>(g, "step");
    const auto time = rd.dataset<double>(g, "time_s"), strain = rd.dataset<double>(g, "strain");
    const auto st = rd.dataset<double>(g, "stress_top_pa"), sb = rd.dataset<double>(g, "stress_bottom_pa");
    const auto ek = rd.dataset<double>(g, "kinetic_j"), es = rd.dataset<double>(g, "strain_energy_j");
    const std::array<std::vector<std::int32_t>, 4> broken = {
        rd.dataset<std::int32_t>(g, "broken_rock_tensile"), rd.dataset<std::int32_t>(g, "broken_rock_shear"),
        rd.dataset<std::int32_t>(g, "broken_joint_tensile"), rd.dataset<std::int32_t>(g, "broken_joint_shear")};
    const std::size_t n = step.size();
    const auto lat = H5Lexists(g, "lateral_strain", H5P_DEFAULT) > 0 ? rd.dataset<double>(g, "lateral_strain")
                                                                    : std::vector<double>(n, 0.0);
    for (const auto* v : {&time, &strain, &st, &sb, &ek, &es, &lat})
      if (v->size() != n) fail(path.string(), "reading /history (columns of different lengths)");
    for (const auto& v : broken)
      if (v.size() != n) fail(path.string(), "reading /history (columns of different lengths)");
    out.curve.resize(n);
    for (std::size_t k = 0; k < n; ++k) {
      CurvePoint& p = out.curve[k];
      p.step = step[k], p.time = time[k], p.strain = strain[k], p.stress_top = st[k], p.stress_bottom = sb[k];
      p.kinetic = ek[k], p.strain_energy = es[k], p.lateral_strain = lat[k];
      for (std::size_t c = 0; c < 4; ++c) p.broken[c] = broken[c][k];
    }
  }

  {
    const Id g = rd.group(file, "cracks");
    const auto time = rd.dataset<double>(g, "time_s"), strain = rd.dataset<double>(g, "strain");
    const auto x = rd.dataset<double>(g, "x_m"), y = rd.dataset<double>(g, "y_m");
    const auto sigma = rd.dataset<double>(g, "sigma_pa"), tau = rd.dataset<double>(g, "tau_pa");
    const auto kind = rd.dataset<std::int32_t>(g, "kind"), mode = rd.dataset<std::int32_t>(g, "mode");
    const auto bond = rd.dataset<std::int32_t>(g, "bond");
    const std::size_t n = time.size();
    for (const auto* v : {&strain, &x, &y, &sigma, &tau})
      if (v->size() != n) fail(path.string(), "reading /cracks (columns of different lengths)");
    for (const auto* v : {&kind, &mode, &bond})
      if (v->size() != n) fail(path.string(), "reading /cracks (columns of different lengths)");
    out.cracks.resize(n);
    for (std::size_t k = 0; k < n; ++k) {
      Crack& c = out.cracks[k];
      c.time = time[k], c.strain = strain[k], c.x = x[k], c.y = y[k], c.sigma = sigma[k], c.tau = tau[k];
      c.kind = BondKind(kind[k]), c.mode = BreakMode(mode[k]), c.bond = bond[k];
    }
  }

  {
    const Id g = rd.group(file, "frames");
    const auto count = rd.attribute<std::int64_t>(g, "count");
    out.frames.resize(std::size_t(std::max<std::int64_t>(count, 0)));
    for (std::size_t k = 0; k < out.frames.size(); ++k) {
      const Id fg = rd.group(g, frame_name(k));
      Frame& f = out.frames[k];
      f.step = long(rd.attribute<std::int64_t>(fg, "step"));
      f.time = rd.attribute<double>(fg, "time");
      f.strain = rd.attribute<double>(fg, "strain");
      f.stress = rd.attribute<double>(fg, "stress");
      f.label = rd.attribute_string(fg, "label");
      f.cracks = std::size_t(rd.attribute<std::int64_t>(fg, "cracks"));
      if (with_positions) {
        f.x = rd.dataset<double>(fg, "x");
        f.y = rd.dataset<double>(fg, "y");
        f.theta = rd.dataset<double>(fg, "theta");
      }
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
