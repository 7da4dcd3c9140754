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

#include "io/checkpoint.hpp"
#include "io/results.hpp"

namespace rbdem::io {

namespace {

// ---------------------------------------------------------------------------------------------------------------
// Small RAII layer over the HDF5 C API: every id is closed by its owner, every failure becomes an exception that
// names the file and the object.

class Id {
 public:
  Id() = default;
  Id(hid_t id, herr_t (*close)(hid_t)) : id_(id), close_(close) {}
  Id(const Id&) = delete;
  Id& operator=(const Id&) = delete;
  Id(Id&& o) noexcept : id_(std::exchange(o.id_, H5I_INVALID_HID)), close_(o.close_) {}
  Id& operator=(Id&& o) noexcept {
    if (this != &o) {
      reset();
      id_ = std::exchange(o.id_, H5I_INVALID_HID);
      close_ = o.close_;
    }
    return *this;
  }
  ~Id() { reset(); }
  hid_t get() const { return id_; }
  operator hid_t() const { return id_; }  // NOLINT: reads like the C API it wraps
  void reset() {
    if (id_ >= 0 && close_) close_(id_);
    id_ = H5I_INVALID_HID;
  }
  // Closes now and reports whether HDF5 managed (closing a file writes its last metadata: a full disk shows here).
  bool close() {
    const bool good = id_ < 0 || !close_ || close_(id_) >= 0;
    id_ = H5I_INVALID_HID;
    return good;
  }

 private:
  hid_t id_ = H5I_INVALID_HID;
  herr_t (*close_)(hid_t) = nullptr;
};

// Silences HDF5's error stack printing while probing (is this an HDF5 file? does this path exist?), where a "no"
// is an answer, not an error. Restores the previous handler.
class QuietHdf5Errors {
 public:
  QuietHdf5Errors() {
    H5Eget_auto2(H5E_DEFAULT, &func_, &data_);
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  }
  QuietHdf5Errors(const QuietHdf5Errors&) = delete;
  QuietHdf5Errors& operator=(const QuietHdf5Errors&) = delete;
  ~QuietHdf5Errors() { H5Eset_auto2(H5E_DEFAULT, func_, data_); }

 private:
  H5E_auto2_t func_ = nullptr;
  void* data_ = nullptr;
};

[[noreturn]] void fail(const std::string& file, const std::string& what) {
  throw std::runtime_error(fmt::format("HDF5: {} failed for {}", what, file));
}

// File and memory types of the element types we store.
template <class T>
struct H5Type;
template <>
struct H5Type<double> {
  static hid_t file() { return H5T_IEEE_F64LE; }
  static hid_t mem() { return H5T_NATIVE_DOUBLE; }
};
template <>
struct H5Type<float> {
  static hid_t file() { return H5T_IEEE_F32LE; }
  static hid_t mem() { return H5T_NATIVE_FLOAT; }
};
template <>
struct H5Type<std::int32_t> {
  static hid_t file() { return H5T_STD_I32LE; }
  static hid_t mem() { return H5T_NATIVE_INT32; }
};
static_assert(std::is_same_v<int, std::int32_t>, "mesh and bond indices (int) are stored as int32");
template <>
struct H5Type<std::int64_t> {
  static hid_t file() { return H5T_STD_I64LE; }
  static hid_t mem() { return H5T_NATIVE_INT64; }
};

constexpr unsigned deflate_level = 4;
constexpr std::size_t compress_above_bytes = 4096;     // smaller datasets are stored contiguous
constexpr std::size_t chunk_target_bytes = 1u << 20;   // HDF5's default chunk cache is 1 MiB

class Writer {
 public:
  explicit Writer(std::string file) : file_(std::move(file)) {}

  // The file is built in memory (HDF5's core driver, no backing store) and written by save(): HDF5 never meets a
  // full disk itself (after a failed write its library state is broken and it crashes at exit), and the bytes go
  // through write_file_checked, which reports a short write.
  Id create_file() const {
    Id fapl(H5Pcreate(H5P_FILE_ACCESS), H5Pclose);
    if (fapl < 0 || H5Pset_fapl_core(fapl, 1 << 20, 0) < 0) fail(file_, "setting up the in-memory file");
    Id f(H5Fcreate(file_.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, fapl), H5Fclose);
    if (f < 0) fail(file_, "creating the file");
    return f;
  }

  // Closes the in-memory file and writes its image to disk, every write checked.
  void save(Id& file) const {
    if (H5Fflush(file, H5F_SCOPE_LOCAL) < 0) fail(file_, "flushing the file");
    const ssize_t n = H5Fget_file_image(file, nullptr, 0);
    if (n < 0) fail(file_, "sizing the file image");
    std::string image(std::size_t(n), '\0');
    if (H5Fget_file_image(file, image.data(), image.size()) < 0) fail(file_, "copying the file image");
    if (!file.close()) fail(file_, "closing the file");
    write_file_checked(file_, image);
  }

  Id group(hid_t loc, const std::string& name) const {
    Id g(H5Gcreate2(loc, name.c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose);
    if (g < 0) fail(file_, "creating group " + name);
    return g;
  }

  // A dataset of `dims` (row-major) from `data`; chunked, shuffled and deflated when it is more than a few KB.
  template <class T>
  void dataset(hid_t loc, const std::string& name, const T* data, const std::vector<hsize_t>& dims) const {
    Id space(H5Screate_simple(int(dims.size()), dims.data(), nullptr), H5Sclose);
    if (space < 0) fail(file_, "creating the dataspace of " + name);
    Id dcpl(H5Pcreate(H5P_DATASET_CREATE), H5Pclose);
    hsize_t n = 1;
    for (const hsize_t d : dims) n *= d;
    if (n * sizeof(T) > compress_above_bytes) {
      std::vector<hsize_t> chunk = dims;
      const hsize_t row = (n / dims[0]) * sizeof(T);
      chunk[0] = std::clamp<hsize_t>(chunk_target_bytes / row, 1, dims[0]);
      if (H5Pset_chunk(dcpl, int(chunk.size()), chunk.data()) < 0 || H5Pset_shuffle(dcpl) < 0 ||
          H5Pset_deflate(dcpl, deflate_level) < 0)
        fail(file_, "setting chunking and compression of " + name);
    }
    Id ds(H5Dcreate2(loc, name.c_str(), H5Type<T>::file(), space, H5P_DEFAULT, dcpl, H5P_DEFAULT), H5Dclose);
    if (ds < 0) fail(file_, "creating dataset " + name);
    if (n > 0 && H5Dwrite(ds, H5Type<T>::mem(), H5S_ALL, H5S_ALL, H5P_DEFAULT, data) < 0)
      fail(file_, "writing dataset " + name);
  }
  template <class T>
  void dataset(hid_t loc, const std::string& name, const std::vector<T>& v) const {
    dataset(loc, name, v.data(), {hsize_t(v.size())});
  }
  template <class T>
  void dataset(hid_t loc, const std::string& name, const std::vector<T>& v, hsize_t columns) const {
    dataset(loc, name, v.data(), {hsize_t(v.size() / columns), columns});
  }

  template <class T>
  void attribute(hid_t loc, const std::string& name, T value) const {
    Id space(H5Screate(H5S_SCALAR), H5Sclose);
    Id a(H5Acreate2(loc, name.c_str(), H5Type<T>::file(), space, H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
    if (a < 0 || H5Awrite(a, H5Type<T>::mem(), &value) < 0) fail(file_, "writing attribute " + name);
  }

  // Variable-length UTF-8 strings: h5py reads them as str, and they have no size limit.
  void attribute(hid_t loc, const std::string& name, const std::string& value) const {
    attribute_strings(loc, name, {value}, true);
  }
  void attribute_strings(hid_t loc, const std::string& name, const std::vector<std::string>& values,
                         bool scalar = false) const {
    Id type(H5Tcopy(H5T_C_S1), H5Tclose);
    if (type < 0 || H5Tset_size(type, H5T_VARIABLE) < 0 || H5Tset_cset(type, H5T_CSET_UTF8) < 0)
      fail(file_, "making the string type of attribute " + name);
    const hsize_t n = values.size();
    Id space(scalar ? H5Screate(H5S_SCALAR) : H5Screate_simple(1, &n, nullptr), H5Sclose);
    std::vector<const char*> p;
    for (const auto& s : values) p.push_back(s.c_str());
    Id a(H5Acreate2(loc, name.c_str(), type, space, H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
    if (a < 0 || H5Awrite(a, type, p.data()) < 0) fail(file_, "writing attribute " + name);
  }

 private:
  std::string file_;
};

// ---------------------------------------------------------------------------------------------------------------
// Reading.

class Reader {
 public:
  explicit Reader(std::string file) : file_(std::move(file)) {}

  Id open_file() const {
    bool is_hdf5 = false;
    {
      const QuietHdf5Errors quiet;
      is_hdf5 = H5Fis_hdf5(file_.c_str()) > 0;
    }
    if (!is_hdf5) fail(file_, "opening (missing, or not an HDF5 file)");
    Id f(H5Fopen(file_.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose);
    if (f < 0) fail(file_, "opening the file");
    return f;
  }

  Id group(hid_t loc, const std::string& name) const {
    if (H5Lexists(loc, name.c_str(), H5P_DEFAULT) <= 0) fail(file_, "finding group " + name + " (not a result.h5?)");
    Id g(H5Gopen2(loc, name.c_str(), H5P_DEFAULT), H5Gclose);
    if (g < 0) fail(file_, "opening group " + name);
    return g;
  }

  template <class T>
  std::vector<T> dataset(hid_t loc, const std::string& name, std::vector<hsize_t>* dims_out = nullptr) const {
    if (H5Lexists(loc, name.c_str(), H5P_DEFAULT) <= 0) fail(file_, "finding dataset " + name);
    Id ds(H5Dopen2(loc, name.c_str(), H5P_DEFAULT), H5Dclose);
    if (ds < 0) fail(file_, "opening dataset " + name);
    Id space(H5Dget_space(ds), H5Sclose);
    const int rank = H5Sget_simple_extent_ndims(space);
    if (rank < 0) fail(file_, "reading the shape of " + name);
    std::vector<hsize_t> dims(std::size_t(rank), 0);
    H5Sget_simple_extent_dims(space, dims.data(), nullptr);
    hsize_t n = 1;
    for (const hsize_t d : dims) n *= d;
    std::vector<T> v(n);
    if (n > 0 && H5Dread(ds, H5Type<T>::mem(), H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data()) < 0)
      fail(file_, "reading dataset " + name);
    if (dims_out) *dims_out = dims;
    return v;
  }

  template <class T>
  T attribute(hid_t loc, const std::string& name) const {
    Id a(H5Aopen(loc, name.c_str(), H5P_DEFAULT), H5Aclose);
    T value{};
    if (a < 0 || H5Aread(a, H5Type<T>::mem(), &value) < 0) fail(file_, "reading attribute " + name);
    return value;
  }

  std::vector<std::string> attribute_strings(hid_t loc, const std::string& name) const {
    if (H5Aexists(loc, name.c_str()) <= 0) fail(file_, "finding attribute " + name);
    Id a(H5Aopen(loc, name.c_str(), H5P_DEFAULT), H5Aclose);
    if (a < 0) fail(file_, "opening attribute " + name);
    Id ftype(H5Aget_type(a), H5Tclose);
    Id space(H5Aget_space(a), H5Sclose);
    const hssize_t n = H5Sget_simple_extent_npoints(space);
    if (H5Tget_class(ftype) != H5T_STRING || n < 0) fail(file_, "reading attribute " + name + " (not a string)");
    std::vector<std::string> out;
    if (H5Tis_variable_str(ftype) > 0) {
      Id mtype(H5Tcopy(H5T_C_S1), H5Tclose);
      H5Tset_size(mtype, H5T_VARIABLE);
      H5Tset_cset(mtype, H5Tget_cset(ftype));
      std::vector<char*> p(std::size_t(n), nullptr);
      if (H5Aread(a, mtype, p.data()) < 0) fail(file_, "reading attribute " + name);
      for (char* s : p) {
        out.emplace_back(s ? s : "");
        H5free_memory(s);
      }
    } else {  // fixed-length strings (as other tools may write them)
      const std::size_t size = H5Tget_size(ftype);
      std::vector<char> buf(size * std::size_t(n));
      if (H5Aread(a, ftype, buf.data()) < 0) fail(file_, "reading attribute " + name);
      for (hssize_t k = 0; k < n; ++k) {
        const char* s = buf.data() + std::size_t(k) * size;
        out.emplace_back(s, std::find(s, s + size, '\0'));
      }
    }
    return out;
  }
  std::string attribute_string(hid_t loc, const std::string& name) const {
    auto v = attribute_strings(loc, name);
    if (v.size() != 1) fail(file_, "reading attribute " + name + " (expected one string)");
    return v.front();
  }

 private:
  std::string file_;
};

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

void check_consistent(const TriMesh& mesh, const Topology& topo, const UcsResult& r) {
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
                   const UcsResult& r) {
  const Writer w(tmp);
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
      std::vector<double> time(n), strain(n), st(n), sb(n), ek(n), es(n);
      std::array<std::vector<std::int32_t>, 4> broken;
      for (auto& v : broken) v.resize(n);
      for (std::size_t k = 0; k < n; ++k) {
        const CurvePoint& p = r.curve[k];
        step[k] = p.step, time[k] = p.time, strain[k] = p.strain, st[k] = p.stress_top, sb[k] = p.stress_bottom;
        ek[k] = p.kinetic, es[k] = p.strain_energy;
        for (std::size_t c = 0; c < 4; ++c) broken[c][k] = p.broken[c];
      }
      w.dataset(g, "step", step), w.dataset(g, "time_s", time), w.dataset(g, "strain", strain);
      w.dataset(g, "stress_top_pa", st), w.dataset(g, "stress_bottom_pa", sb);
      w.dataset(g, "kinetic_j", ek), w.dataset(g, "strain_energy_j", es);
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
      w.attribute(g, "json", ucs_summary(scene, r).dump(2));
    }
    w.save(file);
  }  // the file is closed here, before the caller renames it
}

}  // namespace

// Debian's HDF5 is built without thread safety: every call into it, from any thread (sweeps write several runs at
// once), goes through this lock.
static std::mutex& hdf5_lock() {
  static std::mutex m;
  return m;
}

void write_result_h5(const std::filesystem::path& path, const Scene& scene, const TriMesh& mesh, const Topology& topo,
                     const UcsResult& r) {
  check_consistent(mesh, topo, r);
  const std::lock_guard<std::mutex> lock(hdf5_lock());
  const std::string tmp = path.string() + ".tmp";
  try {
    write_h5_file(tmp, scene, mesh, topo, r);
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
  const std::lock_guard<std::mutex> lock(hdf5_lock());
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
    for (const auto* v : {&time, &strain, &st, &sb, &ek, &es})
      if (v->size() != n) fail(path.string(), "reading /history (columns of different lengths)");
    for (const auto& v : broken)
      if (v.size() != n) fail(path.string(), "reading /history (columns of different lengths)");
    out.curve.resize(n);
    for (std::size_t k = 0; k < n; ++k) {
      CurvePoint& p = out.curve[k];
      p.step = step[k], p.time = time[k], p.strain = strain[k], p.stress_top = st[k], p.stress_bottom = sb[k];
      p.kinetic = ek[k], p.strain_energy = es[k];
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
  const std::lock_guard<std::mutex> lock(hdf5_lock());
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

// ---------------------------------------------------------------------------------------------------------------
// checkpoint.h5 (io/checkpoint.hpp).

namespace {

constexpr int checkpoint_version = 2;  // 2: softening bonds (engine/drive)

void write_curve(const Writer& w, hid_t loc, const std::string& name, const std::vector<CurvePoint>& curve) {
  const Id g = w.group(loc, name);
  std::vector<std::int64_t> step;
  std::vector<double> d;
  std::vector<std::int32_t> broken;
  for (const auto& p : curve) {
    step.push_back(p.step);
    d.insert(d.end(), {p.time, p.strain, p.stress_top, p.stress_bottom, p.kinetic, p.strain_energy});
    broken.insert(broken.end(), p.broken.begin(), p.broken.end());
  }
  w.dataset(g, "step", step);
  w.dataset(g, "values", d.data(), {hsize_t(curve.size()), 6});
  w.dataset(g, "broken", broken.data(), {hsize_t(curve.size()), 4});
}

std::vector<CurvePoint> read_curve(const Reader& rd, hid_t loc, const std::string& name) {
  const Id g = rd.group(loc, name);
  const auto step = rd.dataset<std::int64_t>(g, "step");
  const auto d = rd.dataset<double>(g, "values");
  const auto broken = rd.dataset<std::int32_t>(g, "broken");
  std::vector<CurvePoint> curve(step.size());
  if (d.size() != 6 * step.size() || broken.size() != 4 * step.size()) throw std::runtime_error("bad curve " + name);
  for (std::size_t k = 0; k < curve.size(); ++k) {
    CurvePoint& p = curve[k];
    p.step = step[k];
    p.time = d[6 * k], p.strain = d[6 * k + 1], p.stress_top = d[6 * k + 2], p.stress_bottom = d[6 * k + 3];
    p.kinetic = d[6 * k + 4], p.strain_energy = d[6 * k + 5];
    for (int c = 0; c < 4; ++c) p.broken[std::size_t(c)] = broken[4 * k + std::size_t(c)];
  }
  return curve;
}

void write_frame(const Writer& w, hid_t loc, const std::string& name, const Frame& f) {
  const Id g = w.group(loc, name);
  w.attribute(g, "step", std::int64_t(f.step));
  w.attribute(g, "time", f.time);
  w.attribute(g, "strain", f.strain);
  w.attribute(g, "stress", f.stress);
  w.attribute(g, "label", f.label);
  w.attribute(g, "cracks", std::int64_t(f.cracks));
  w.dataset(g, "x", f.x);
  w.dataset(g, "y", f.y);
  w.dataset(g, "theta", f.theta);
}

Frame read_frame(const Reader& rd, hid_t loc, const std::string& name) {
  const Id g = rd.group(loc, name);
  Frame f;
  f.step = rd.attribute<std::int64_t>(g, "step");
  f.time = rd.attribute<double>(g, "time");
  f.strain = rd.attribute<double>(g, "strain");
  f.stress = rd.attribute<double>(g, "stress");
  f.label = rd.attribute_string(g, "label");
  f.cracks = std::size_t(rd.attribute<std::int64_t>(g, "cracks"));
  f.x = rd.dataset<double>(g, "x");
  f.y = rd.dataset<double>(g, "y");
  f.theta = rd.dataset<double>(g, "theta");
  return f;
}

template <class T>
std::vector<std::int32_t> as_int32(const std::vector<T>& v) {
  std::vector<std::int32_t> out(v.size());
  for (std::size_t k = 0; k < v.size(); ++k) out[k] = std::int32_t(v[k]);
  return out;
}

// Plain-old-data records stored as rows of doubles (bit-exact round trip).
template <class T>
void write_rows(const Writer& w, hid_t loc, const std::string& name, const std::vector<T>& v) {
  static_assert(sizeof(T) % sizeof(double) == 0 && std::is_trivially_copyable_v<T>);
  constexpr hsize_t cols = sizeof(T) / sizeof(double);
  std::vector<double> d(v.size() * cols);
  if (!v.empty()) std::memcpy(d.data(), v.data(), d.size() * sizeof(double));
  w.dataset(loc, name, d.data(), {hsize_t(v.size()), cols});
}

template <class T>
std::vector<T> read_rows(const Reader& rd, hid_t loc, const std::string& name) {
  constexpr std::size_t cols = sizeof(T) / sizeof(double);
  const auto d = rd.dataset<double>(loc, name);
  if (d.size() % cols != 0) throw std::runtime_error("bad dataset " + name);
  std::vector<T> v(d.size() / cols);
  if (!v.empty()) std::memcpy(static_cast<void*>(v.data()), d.data(), d.size() * sizeof(double));
  return v;
}

void write_checkpoint_file(const std::string& tmp, const UcsCheckpoint& c) {
  const Writer w(tmp);
  Id file = w.create_file();
  w.attribute(file, "format", std::string("rbdem checkpoint"));
  w.attribute(file, "version", std::int32_t(checkpoint_version));
  w.attribute(file, "scene_toml", c.scene_toml);
  const Engine::Snapshot& e = c.engine;
  {
    const Id g = w.group(file, "engine");
    write_rows(w, g, "state", e.state);
    w.dataset(g, "fx", e.fx);
    w.dataset(g, "fy", e.fy);
    w.dataset(g, "moment", e.moment);
    w.dataset(g, "free_face", as_int32(e.free_face));
    w.dataset(g, "broken", as_int32(e.broken));
    w.dataset(g, "fs_lin", e.fs_lin);
    w.dataset(g, "drive", e.drive);
    write_rows(w, g, "slot", e.slot);
    w.dataset(g, "eligible", e.eligible);
    w.dataset(g, "top_candidates", e.top_candidates);
    w.dataset(g, "bottom_candidates", e.bottom_candidates);
    w.dataset(g, "ref_x", e.ref_x);
    w.dataset(g, "ref_y", e.ref_y);
    w.dataset(g, "top_fs", e.top_fs);
    w.dataset(g, "bottom_fs", e.bottom_fs);
    const std::pair<const char*, double> reals[] = {
        {"dt", e.dt},         {"time", e.time},           {"platen_velocity", e.platen_velocity},
        {"strain_for_log", e.strain_for_log},             {"top_y", e.top_y},
        {"top_force", e.top_force}, {"bottom_force", e.bottom_force}, {"ref_top", e.ref_top},
        {"e_damping", e.e_damping}, {"e_friction", e.e_friction}, {"e_work", e.e_work},
        {"platen_energy", e.platen_energy}};
    for (const auto& [name, value] : reals) w.attribute(g, name, value);
    w.attribute(g, "steps", std::int64_t(e.steps));
    w.attribute(g, "breakage", std::int32_t(e.breakage));
    w.attribute(g, "rebuild", std::int32_t(e.rebuild));
    const Id cg = w.group(g, "contacts");
    const auto& C = e.contacts;
    w.dataset(cg, "i", C.i);
    w.dataset(cg, "j", C.j);
    w.dataset(cg, "bond", C.bond);
    write_rows(w, cg, "law", C.law);
    w.dataset(cg, "fs", C.fs);
    w.dataset(cg, "fn", C.fn);
    w.dataset(cg, "chord", C.chord);
    std::vector<std::int64_t> key(C.key.begin(), C.key.end());
    w.dataset(cg, "key", key);
    const Id kg = w.group(g, "cracks");
    std::vector<double> d;
    std::vector<std::int32_t> bond, kind, mode;
    for (const Crack& k : e.cracks) {
      d.insert(d.end(), {k.time, k.strain, k.x, k.y, k.sigma, k.tau});
      bond.push_back(k.bond), kind.push_back(int(k.kind)), mode.push_back(int(k.mode));
    }
    w.dataset(kg, "values", d.data(), {hsize_t(e.cracks.size()), 6});
    w.dataset(kg, "bond", bond);
    w.dataset(kg, "kind", kind);
    w.dataset(kg, "mode", mode);
  }
  {
    const Id g = w.group(file, "driver");
    const UcsResult& p = c.partial;
    const std::pair<const char*, double> reals[] = {
        {"dt", p.dt}, {"dt_critical", p.dt_critical}, {"dt_block_estimate", p.dt_block_estimate},
        {"elastic_start_strain", p.elastic_start_strain}, {"energy_ratio_max", p.energy_ratio_max},
        {"wall_seconds", p.wall_seconds}, {"next_frame", c.next_frame}, {"peak", c.peak}, {"energy0", c.energy0}};
    for (const auto& [name, value] : reals) w.attribute(g, name, value);
    w.attribute(g, "sample_every", std::int64_t(c.sample_every));
    w.attribute(g, "peak_step", std::int64_t(c.peak_step));
    w.attribute(g, "peak_detail_step", std::int64_t(c.peak_detail_step));
    write_curve(w, g, "curve", p.curve);
    write_curve(w, g, "at_peak", {c.at_peak});
    write_frame(w, g, "peak_frame", c.peak_frame);
    const Id fg = w.group(g, "frames");
    w.attribute(fg, "count", std::int64_t(p.frames.size()));
    for (std::size_t k = 0; k < p.frames.size(); ++k) write_frame(w, fg, frame_name(k), p.frames[k]);
  }
  w.save(file);
}

UcsCheckpoint read_checkpoint_file(const std::string& path) {
  const Reader rd(path);
  const Id file = rd.open_file();
  UcsCheckpoint c;
  if (H5Aexists(file, "format") <= 0 || rd.attribute_string(file, "format") != "rbdem checkpoint")
    fail(path, "reading (not an rbdem checkpoint)");
  if (rd.attribute<std::int32_t>(file, "version") != checkpoint_version)
    fail(path, "reading (a checkpoint of another rbdem version: start afresh without --resume)");
  c.scene_toml = rd.attribute_string(file, "scene_toml");
  Engine::Snapshot& e = c.engine;
  {
    const Id g = rd.group(file, "engine");
    e.state = read_rows<BlockState>(rd, g, "state");
    e.fx = rd.dataset<double>(g, "fx");
    e.fy = rd.dataset<double>(g, "fy");
    e.moment = rd.dataset<double>(g, "moment");
    for (int v : rd.dataset<std::int32_t>(g, "free_face")) e.free_face.push_back(std::uint8_t(v));
    for (int v : rd.dataset<std::int32_t>(g, "broken")) e.broken.push_back(std::uint8_t(v));
    e.fs_lin = rd.dataset<double>(g, "fs_lin");
    e.drive = rd.dataset<double>(g, "drive");
    e.slot = read_rows<BondSlot>(rd, g, "slot");
    e.eligible = rd.dataset<std::int32_t>(g, "eligible");
    e.top_candidates = rd.dataset<std::int32_t>(g, "top_candidates");
    e.bottom_candidates = rd.dataset<std::int32_t>(g, "bottom_candidates");
    e.ref_x = rd.dataset<double>(g, "ref_x");
    e.ref_y = rd.dataset<double>(g, "ref_y");
    e.top_fs = rd.dataset<double>(g, "top_fs");
    e.bottom_fs = rd.dataset<double>(g, "bottom_fs");
    const std::pair<const char*, double*> reals[] = {
        {"dt", &e.dt}, {"time", &e.time}, {"platen_velocity", &e.platen_velocity},
        {"strain_for_log", &e.strain_for_log}, {"top_y", &e.top_y}, {"top_force", &e.top_force},
        {"bottom_force", &e.bottom_force}, {"ref_top", &e.ref_top}, {"e_damping", &e.e_damping},
        {"e_friction", &e.e_friction}, {"e_work", &e.e_work}, {"platen_energy", &e.platen_energy}};
    for (const auto& [name, value] : reals) *value = rd.attribute<double>(g, name);
    e.steps = rd.attribute<std::int64_t>(g, "steps");
    e.breakage = rd.attribute<std::int32_t>(g, "breakage") != 0;
    e.rebuild = rd.attribute<std::int32_t>(g, "rebuild") != 0;
    const Id cg = rd.group(g, "contacts");
    auto& C = e.contacts;
    C.i = rd.dataset<std::int32_t>(cg, "i");
    C.j = rd.dataset<std::int32_t>(cg, "j");
    C.bond = rd.dataset<std::int32_t>(cg, "bond");
    C.law = read_rows<LinearContact>(rd, cg, "law");
    C.fs = rd.dataset<double>(cg, "fs");
    C.fn = rd.dataset<double>(cg, "fn");
    C.chord = rd.dataset<double>(cg, "chord");
    for (std::int64_t k : rd.dataset<std::int64_t>(cg, "key")) C.key.push_back(std::uint64_t(k));
    const Id kg = rd.group(g, "cracks");
    const auto d = rd.dataset<double>(kg, "values");
    const auto bond = rd.dataset<std::int32_t>(kg, "bond");
    const auto kind = rd.dataset<std::int32_t>(kg, "kind");
    const auto mode = rd.dataset<std::int32_t>(kg, "mode");
    if (d.size() != 6 * bond.size() || kind.size() != bond.size() || mode.size() != bond.size())
      fail(path, "reading the crack log");
    for (std::size_t k = 0; k < bond.size(); ++k) {
      Crack cr;
      cr.time = d[6 * k], cr.strain = d[6 * k + 1], cr.x = d[6 * k + 2], cr.y = d[6 * k + 3];
      cr.sigma = d[6 * k + 4], cr.tau = d[6 * k + 5];
      cr.bond = bond[k], cr.kind = BondKind(kind[k]), cr.mode = BreakMode(mode[k]);
      e.cracks.push_back(cr);
    }
  }
  {
    const Id g = rd.group(file, "driver");
    UcsResult& p = c.partial;
    const std::pair<const char*, double*> reals[] = {
        {"dt", &p.dt}, {"dt_critical", &p.dt_critical}, {"dt_block_estimate", &p.dt_block_estimate},
        {"elastic_start_strain", &p.elastic_start_strain}, {"energy_ratio_max", &p.energy_ratio_max},
        {"wall_seconds", &p.wall_seconds}, {"next_frame", &c.next_frame}, {"peak", &c.peak},
        {"energy0", &c.energy0}};
    for (const auto& [name, value] : reals) *value = rd.attribute<double>(g, name);
    c.sample_every = rd.attribute<std::int64_t>(g, "sample_every");
    c.peak_step = rd.attribute<std::int64_t>(g, "peak_step");
    c.peak_detail_step = rd.attribute<std::int64_t>(g, "peak_detail_step");
    p.curve = read_curve(rd, g, "curve");
    const auto at_peak = read_curve(rd, g, "at_peak");
    if (at_peak.size() != 1) fail(path, "reading the peak sample");
    c.at_peak = at_peak.front();
    c.peak_frame = read_frame(rd, g, "peak_frame");
    const Id fg = rd.group(g, "frames");
    const auto n = rd.attribute<std::int64_t>(fg, "count");
    for (std::int64_t k = 0; k < n; ++k) p.frames.push_back(read_frame(rd, fg, frame_name(std::size_t(k))));
  }
  return c;
}

}  // namespace

void write_checkpoint(const std::filesystem::path& path, const UcsCheckpoint& c) {
  const std::lock_guard<std::mutex> lock(hdf5_lock());
  const std::string tmp = path.string() + ".tmp";
  try {
    write_checkpoint_file(tmp, c);
  } catch (...) {
    std::error_code ec;
    std::filesystem::remove(tmp, ec);  // the previous checkpoint stays as it was
    throw;
  }
  std::filesystem::rename(tmp, path);
}

UcsCheckpoint read_checkpoint(const std::filesystem::path& path) {
  const std::lock_guard<std::mutex> lock(hdf5_lock());
  try {
    return read_checkpoint_file(path.string());
  } catch (const std::runtime_error& e) {
    throw std::runtime_error(fmt::format("cannot resume from {}: {}", path.string(), e.what()));
  }
}

}  // namespace rbdem::io
