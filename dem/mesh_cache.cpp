// The mesh cache. See mesh_cache.hpp.
//
// A cache file holds a header line, the key text, the mesh's arrays as raw bytes and, last, a 64-bit FNV-1a
// checksum of everything before it. A file that does not read back whole, or whose key text differs from the
// scene's, is ignored and written anew. Writers of the same key (runs side by side) each write a file of their own
// and rename it into place, so a reader never sees a file half written.
#include "dem/mesh_cache.hpp"

#include <unistd.h>

#include <atomic>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <optional>
#include <string_view>
#include <system_error>

#include <fmt/format.h>
#include <gmsh.h>

#include "dem/specimen_mesh.hpp"
#include "dem/specimen_mesh3.hpp"
#include "dem/version.hpp"

namespace rbdem {

namespace {

// Bumped whenever the file layout or the meaning of a cached mesh changes (of a triangle mesh, of a tetrahedral one).
constexpr std::string_view header = "rbdem-mesh-cache-1\n";
constexpr std::string_view header3 = "rbdem-mesh3-cache-1\n";

bool starts_with(std::string_view s, std::string_view prefix) { return s.substr(0, prefix.size()) == prefix; }

bool cache_enabled() {
  if (const char* v = std::getenv("RBDEM_MESH_CACHE"); v != nullptr) {
    const std::string_view s(v);
    if (s == "off" || s == "0" || s == "false" || s == "no") return false;
    if (s == "on" || s == "1" || s == "true" || s == "yes") return true;  // any build (tests, development)
  }
  const std::string_view commit = version_commit();
  return !commit.empty() && commit.find("dirty") == std::string_view::npos;
}

class Writer {
 public:
  template <class T> void raw(const std::vector<T>& v) {
    count(v.size());
    out_.append(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
  }
  void text(std::string_view s) {
    count(s.size());
    out_.append(s);
  }
  void count(std::uint64_t n) { out_.append(reinterpret_cast<const char*>(&n), sizeof n); }
  std::string finish() {
    const std::uint64_t sum = fnv1a(out_);
    out_.append(reinterpret_cast<const char*>(&sum), sizeof sum);
    return std::move(out_);
  }

 private:
  std::string out_;
};

// Reads what Writer wrote; every read checks that the bytes are there.
class Reader {
 public:
  explicit Reader(std::string_view in) : in_(in) {}
  bool count(std::uint64_t& n) { return take(&n, sizeof n); }
  template <class T> bool raw(std::vector<T>& v) {
    std::uint64_t n = 0;
    if (!count(n) || n > (in_.size() - at_) / sizeof(T)) return false;
    v.resize(std::size_t(n));
    return take(v.data(), std::size_t(n) * sizeof(T));
  }
  bool text(std::string& s) {
    std::uint64_t n = 0;
    if (!count(n) || n > in_.size() - at_) return false;
    s.assign(in_.substr(at_, std::size_t(n)));
    at_ += std::size_t(n);
    return true;
  }
  bool at_end() const { return at_ == in_.size(); }

 private:
  bool take(void* dst, std::size_t n) {
    if (n > in_.size() - at_) return false;
    if (n > 0) std::memcpy(dst, in_.data() + at_, n);
    at_ += n;
    return true;
  }
  std::string_view in_;
  std::size_t at_ = 0;
};

// The file's body (all but its trailing checksum) when the checksum holds and the body opens with `head` and the
// key text `key_text`: a reader placed after them.
std::optional<Reader> open_body(std::string_view file, std::string_view head, const std::string& key_text,
                                std::string_view& body) {
  if (file.size() < sizeof(std::uint64_t)) return std::nullopt;
  body = file.substr(0, file.size() - sizeof(std::uint64_t));
  std::uint64_t sum = 0;
  std::memcpy(&sum, file.data() + body.size(), sizeof sum);
  if (sum != fnv1a(body)) return std::nullopt;
  Reader r(body);
  std::string h, key;
  if (!r.text(h) || h != head || !r.text(key) || key != key_text) return std::nullopt;
  return r;
}

std::string encode(const std::string& key_text, const TriMesh& m) {
  Writer w;
  w.text(header);
  w.text(key_text);
  w.raw(m.nodes), w.raw(m.triangles), w.raw(m.layer);
  w.count(m.layer_names.size());
  for (const auto& s : m.layer_names) w.text(s);
  w.count(m.interfaces.size());
  for (const auto& i : m.interfaces) w.text(i.name), w.raw(i.edges);
  w.count(m.notes.size());
  for (const auto& s : m.notes) w.text(s);
  return w.finish();
}

std::optional<TriMesh> decode(const std::string& key_text, std::string_view file) {
  std::string_view body;
  std::optional<Reader> opened = open_body(file, header, key_text, body);
  if (!opened) return std::nullopt;
  Reader& r = *opened;
  TriMesh m;
  std::uint64_t n = 0;
  if (!r.raw(m.nodes) || !r.raw(m.triangles) || !r.raw(m.layer)) return std::nullopt;
  // Counts are checked against the bytes left before anything is allocated for them.
  auto sized = [&](auto& v) {
    return r.count(n) && n <= body.size() ? (v.resize(std::size_t(n)), true) : false;
  };
  if (!sized(m.layer_names)) return std::nullopt;
  for (auto& s : m.layer_names)
    if (!r.text(s)) return std::nullopt;
  if (!sized(m.interfaces)) return std::nullopt;
  for (auto& i : m.interfaces)
    if (!r.text(i.name) || !r.raw(i.edges)) return std::nullopt;
  if (!sized(m.notes)) return std::nullopt;
  for (auto& s : m.notes)
    if (!r.text(s)) return std::nullopt;
  if (!r.at_end()) return std::nullopt;
  return m;
}

// A boundary face as five ints (its nodes, its tetrahedron, its tag): the struct's padding is not written.
std::vector<std::array<int, 5>> boundary_rows(const std::vector<BoundaryFace>& faces) {
  std::vector<std::array<int, 5>> rows;
  rows.reserve(faces.size());
  for (const auto& f : faces) rows.push_back({f.nodes[0], f.nodes[1], f.nodes[2], f.tet, int(f.tag)});
  return rows;
}

std::string encode(const std::string& key_text, const TetMesh& m) {
  Writer w;
  w.text(header3);
  w.text(key_text);
  w.raw(m.nodes), w.raw(m.tets), w.raw(m.layer), w.raw(m.layer_rows), w.raw(boundary_rows(m.boundary));
  w.raw(std::vector<double>{m.mesh_seconds});
  w.count(m.layer_names.size());
  for (const auto& s : m.layer_names) w.text(s);
  w.count(m.notes.size());
  for (const auto& s : m.notes) w.text(s);
  return w.finish();
}

std::optional<TetMesh> decode3(const std::string& key_text, std::string_view file) {
  std::string_view body;
  std::optional<Reader> opened = open_body(file, header3, key_text, body);
  if (!opened) return std::nullopt;
  Reader& r = *opened;
  TetMesh m;
  std::vector<std::array<int, 5>> rows;
  std::vector<double> seconds;
  if (!r.raw(m.nodes) || !r.raw(m.tets) || !r.raw(m.layer) || !r.raw(m.layer_rows) || !r.raw(rows) ||
      !r.raw(seconds) || seconds.size() != 1)
    return std::nullopt;
  m.mesh_seconds = seconds[0];
  for (const auto& f : rows) {
    if (f[4] < 0 || f[4] > int(FaceTag::lateral)) return std::nullopt;
    m.boundary.push_back({{f[0], f[1], f[2]}, f[3], FaceTag(f[4])});
  }
  std::uint64_t n = 0;
  for (auto* texts : {&m.layer_names, &m.notes}) {
    if (!r.count(n) || n > body.size()) return std::nullopt;  // checked before anything is allocated for it
    texts->resize(std::size_t(n));
    for (auto& s : *texts)
      if (!r.text(s)) return std::nullopt;
  }
  if (!r.at_end()) return std::nullopt;
  return m;
}

std::optional<TriMesh> decode_as(const TriMesh*, const std::string& key_text, std::string_view file) {
  return decode(key_text, file);
}
std::optional<TetMesh> decode_as(const TetMesh*, const std::string& key_text, std::string_view file) {
  return decode3(key_text, file);
}

}  // namespace

std::uint64_t fnv1a(std::string_view s) {
  std::uint64_t h = 1469598103934665603ull;
  for (unsigned char c : s) h = (h ^ c) * 1099511628211ull;
  return h;
}

std::filesystem::path cache_dir() {
  if (const char* d = std::getenv("RBDEM_CACHE_DIR"); d && *d) return d;
  if (const char* d = std::getenv("XDG_CACHE_HOME"); d && *d) return std::filesystem::path(d) / "rbdem";
  if (const char* d = std::getenv("HOME"); d && *d) return std::filesystem::path(d) / ".cache" / "rbdem";
  return {};
}

std::string mesh_cache_key_text(const Scene& scene) {
  std::string text = fmt::format("{}rbdem={}\ngmsh-api={}\n", header, version_text(), GMSH_API_VERSION);
  for (const auto& p : scene_parameters()) {
    const std::string_view key = p.key;
    if (key == "mesh.strength_seed") continue;
    // Off, it leaves the mesh as it was before the key existed: left out, so that those cache files stay valid.
    if (key == "mesh.structured" && !scene.mesh.structured) continue;
    if (key == "mesh.block_order" && scene.mesh.block_order == "mesh") continue;
    if (starts_with(key, "specimen.") || starts_with(key, "joint_set.") || starts_with(key, "joint_set2.") ||
        starts_with(key, "mesh."))
      text += p.key + "=" + parameter_text(scene, p.key) + "\n";
  }
  return text;
}

namespace {
// The cache file of a scene whose key text is `key_text` ("" when the cache does not apply).
std::filesystem::path cache_file(const Scene& scene, const std::string& key_text) {
  if (!scene.mesh.file.empty() || !cache_enabled()) return {};
  const std::filesystem::path dir = cache_dir();
  if (dir.empty()) return {};
  return dir / fmt::format("mesh-{:016x}.bin", fnv1a(key_text));
}
}  // namespace

std::filesystem::path mesh_cache_file(const Scene& scene) { return cache_file(scene, mesh_cache_key_text(scene)); }

namespace {
// The scene's mesh from the cache file when one holds it, else made by `make` and written there.
template <class Mesh, class Make>
Mesh mesh_through_cache(const Scene& scene, bool* from_cache, const Make& make) {
  if (from_cache) *from_cache = false;
  const std::string key_text = mesh_cache_key_text(scene);
  const std::filesystem::path file = cache_file(scene, key_text);
  if (file.empty()) return make();
  {
    std::ifstream in(file, std::ios::binary);
    if (in) {
      const std::string bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
      if (auto m = decode_as(static_cast<const Mesh*>(nullptr), key_text, bytes)) {
        if (from_cache) *from_cache = true;
        return std::move(*m);
      }
    }
  }
  Mesh mesh = make();
  // The cache only saves time: a folder that cannot be written leaves the run as it is.
  std::error_code ec;
  std::filesystem::create_directories(file.parent_path(), ec);
  // A name of this writer's own: the runs of a sweep are threads of one process.
  static std::atomic<unsigned> writers{0};
  const std::filesystem::path mine = fmt::format("{}.{}.{}", file.string(), ::getpid(), writers++);
  {
    std::ofstream out(mine, std::ios::binary | std::ios::trunc);
    const std::string bytes = encode(key_text, mesh);
    out.write(bytes.data(), std::streamsize(bytes.size()));
    if (!out) {
      out.close();
      std::filesystem::remove(mine, ec);
      return mesh;
    }
  }
  std::filesystem::rename(mine, file, ec);
  if (ec) std::filesystem::remove(mine, ec);
  return mesh;
}
}  // namespace

TriMesh make_mesh_cached(const Scene& scene, bool* from_cache) {
  return mesh_through_cache<TriMesh>(scene, from_cache, [&] { return make_mesh(scene); });
}

TetMesh make_mesh3_cached(const Scene& scene, bool* from_cache) {
  return mesh_through_cache<TetMesh>(scene, from_cache, [&] { return mesh_scene3(scene); });
}

}  // namespace rbdem
