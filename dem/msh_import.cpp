// User meshes: .msh files read through gmsh, after a pre-scan that refuses what gmsh would crash on, and the
// checks every imported mesh must pass. See specimen_mesh.hpp (read_msh, check_user_mesh).
#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include <fmt/format.h>

#include "dem/gmsh_module.hpp"
#include "dem/specimen_mesh.hpp"

namespace rbdem {

namespace {

// The first line of a gmsh mesh file. Anything else is refused before gmsh sees it: gmsh picks a reader by
// extension and content, and would run a file that is not a mesh as a .geo script.
void require_msh_header(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::string first;
  std::error_code ec;
  if (in && !std::filesystem::is_directory(path) && std::filesystem::file_size(path, ec) == 0 && !ec)
    throw SceneError(fmt::format("mesh file '{}' is empty: give a gmsh .msh file", path.string()));
  if (!in || std::filesystem::is_directory(path) || !std::getline(in, first))
    throw SceneError(fmt::format("cannot read mesh file '{}': check --mesh / mesh.file (it must be a readable gmsh "
                                 ".msh file)",
                                 path.string()));
  while (!first.empty() && (first.back() == '\r' || first.back() == ' ' || first.back() == '\t')) first.pop_back();
  if (first != "$MeshFormat")
    throw SceneError(fmt::format("mesh file '{}' is not a gmsh mesh: its first line is not $MeshFormat; export the "
                                 "mesh from gmsh as MSH (File > Export > .msh, version 4.1 or 2.2)",
                                 path.string()));
}

// Nodes per element of the gmsh element types a user mesh may hold (first and second order, points to volumes).
int nodes_of_type(int type) {
  switch (type) {
    case 1: return 2;   case 2: return 3;   case 3: return 4;   case 4: return 4;   case 5: return 8;
    case 6: return 6;   case 7: return 5;   case 8: return 3;   case 9: return 6;   case 10: return 9;
    case 11: return 10; case 15: return 1;  case 16: return 8;  case 17: return 20; case 18: return 15;
    case 19: return 13;
    default: return -1;
  }
}

bool at_end(std::istringstream& ls) {
  std::string extra;
  return !(ls >> extra);
}

// The counts a $Nodes or $Elements header declares (MSH 4.1: `blocks count min-tag max-tag`; MSH 2: `count`) or the
// blocks that follow it hold. gmsh 4.8 allocates its tables from the declared count before it reads a block, so a
// count that the blocks do not hold made it allocate 1.4 GB from a file of a few hundred bytes (found by
// tests/fuzz/fuzz_msh): the header must hold exactly what follows.
struct Counts {
  long long blocks = 1, count = 0, min_tag = 0, max_tag = 0;
  bool v4 = false;

  bool read(std::istringstream& ls, bool msh4) {
    v4 = msh4;
    const bool ok = v4 ? bool(ls >> blocks >> count >> min_tag >> max_tag) : bool(ls >> count);
    return ok && at_end(ls) && blocks >= 0 && count >= 0;
  }
  void add(long long tag) {
    min_tag = count == 0 ? tag : std::min(min_tag, tag);
    max_tag = count == 0 ? tag : std::max(max_tag, tag);
    ++count;
  }
  template <class Bad>
  void require_match(const Counts& found, const char* what, Bad bad) const {
    if (found.count != count)
      throw bad(fmt::format("the header declares {} {}s and the file holds {}", count, what, found.count));
    if (v4 && count > 0 && (found.min_tag != min_tag || found.max_tag != max_tag))
      throw bad(fmt::format("the header declares {} tags {} to {} and the file holds {} to {}", what, min_tag,
                            max_tag, found.min_tag, found.max_tag));
  }
};

// The numbers on the rest of a line: their count, or -1 when a token is not a number. gmsh reads numbers regardless
// of lines: one number too many or too few shifts every later node (gmsh 4.8 then crashes, found by
// tests/fuzz/fuzz_msh), so each line must hold exactly its numbers.
int count_numbers(std::istringstream& l) {
  int numbers_read = 0;
  for (double x = 0; l >> x; ++numbers_read) {
  }
  if (!l.eof()) return -1;  // a token that is not a number
  return numbers_read;
}

// One pass of prescan_msh over a file: the stream, the line last read, what the $MeshFormat line declares and the
// node tags seen so far. Each section has its own scan below.
class MshPrescan {
 public:
  explicit MshPrescan(const std::filesystem::path& path) : path_(path), in_(path, std::ios::binary) {}

  void run() {
    std::getline(in_, line_);  // $MeshFormat, checked by require_msh_header
    read_format();
    std::set<std::string> headers;
    while (std::getline(in_, line_)) {
      check_length();
      while (!line_.empty() && (line_.back() == '\r' || line_.back() == ' ' || line_.back() == '\t')) line_.pop_back();
      if (!line_.empty() && line_[0] == '$') check_section_header(headers);
      if (line_ == "$PhysicalNames") scan_physical_names();
      if (line_ == "$Entities" && v4_) scan_entities();
      if (line_ == "$Nodes")
        scan_nodes();
      else if (line_ == "$Elements")
        scan_elements();
    }
  }

 private:
  // The line after $MeshFormat: `version file-type data-size`. Only what the scan understands reaches gmsh: gmsh
  // 4.8 reads a damaged MSH 3 or binary file without checking its counts, and tests/fuzz/fuzz_msh made it allocate
  // 3.4 GB from a file of 199 bytes.
  void read_format() {
    int binary = 0;
    {
      std::getline(in_, line_);
      std::istringstream head(line_);
      if (!(head >> version_ >> binary))
        throw SceneError(fmt::format("mesh file '{}': the line after $MeshFormat must read `version file-type "
                                     "data-size` (e.g. `4.1 0 8`); export the mesh from gmsh again",
                                     path_.string()));
    }
    if (!((version_ >= 2.0 && version_ < 3.0) || (version_ >= 4.0 && version_ < 5.0)))
      throw SceneError(fmt::format("mesh file '{}' is MSH version {:g}, which rbdem does not read: export the mesh "
                                   "from gmsh as MSH 4.1 or 2.2 (File > Export, or `gmsh -2 -format msh41`)",
                                   path_.string(), version_));
    if (binary != 0)
      throw SceneError(fmt::format("mesh file '{}' is {}: rbdem reads ASCII .msh files only (it checks a mesh "
                                   "before gmsh reads it); export it again without `Save in binary format` (or "
                                   "with `Mesh.Binary = 0;`)",
                                   path_.string(), binary == 1 ? "a binary .msh file" : "of an unknown file type"));
    if (version_ >= 4.0 && version_ < 4.1)
      throw SceneError(fmt::format("mesh file '{}' is MSH version {:g}, whose node layout rbdem does not read: "
                                   "export the mesh from gmsh as MSH 4.1 or 2.2 (`gmsh -2 -format msh41`)",
                                   path_.string(), version_));
    v4_ = version_ >= 4.0;
  }

  // The error for a file that breaks the MSH layout.
  SceneError bad(const std::string& what) const {
    return SceneError(fmt::format("mesh file '{}' is malformed: {}; export the mesh from gmsh again", path_.string(),
                                  what));
  }

  // gmsh reads a line in pieces of 255 (MSH 2) or 1023 (MSH 4) characters when it looks for the next section, so a
  // piece of a longer line that starts with '$' would open a section this scan never saw.
  void check_length() const {
    const std::size_t longest = v4_ ? 1000 : 250;
    if (line_.size() > longest)
      throw bad(fmt::format("a line holds {} characters, more than the {} gmsh reads at once", line_.size(), longest));
  }

  // The next line of `section` into ls_; throws when the file ends.
  void read_line(const char* section) {
    if (!std::getline(in_, line_)) throw bad(fmt::format("the {} section ends early", section));
    check_length();
    ls_.clear();
    ls_.str(line_);
  }

  // gmsh opens a section at any line that starts with '$' and runs the reader whose name begins the line
  // ("$ElementsX" is read as $Elements, "$NOD" and "$ELM" as MSH 1; found by tests/fuzz/fuzz_msh), and a second
  // $MeshFormat would switch it to binary: only the exact headers of a plain mesh, each once, get past.
  void check_section_header(std::set<std::string>& headers) const {
    static const std::set<std::string> known = {"$MeshFormat", "$EndMeshFormat", "$PhysicalNames",
                                                "$EndPhysicalNames", "$Entities", "$EndEntities",
                                                "$Nodes", "$EndNodes", "$Elements", "$EndElements"};
    if (!known.count(line_) || line_ == "$MeshFormat" || !headers.insert(line_).second)
      throw SceneError(fmt::format("mesh file '{}': the section header `{}` is not one rbdem reads or appears "
                                   "twice; rbdem reads $MeshFormat, then $PhysicalNames, $Entities, $Nodes and "
                                   "$Elements once each: export the mesh alone from gmsh (File > Export > .msh, no "
                                   "views or data)",
                                   path_.string(), line_.substr(0, std::min<std::size_t>(line_.size(), 40))));
  }

  // gmsh 4.8 keeps one position per dimension and indexes it by the dimension read from the file (a dimension
  // outside 0-3 crashed it, found by tests/fuzz/fuzz_msh): every name line is `dim tag "name"` with dim 0-3.
  void scan_physical_names() {
    long long count = 0;
    read_line("$PhysicalNames");
    std::string extra;
    if (!(ls_ >> count) || count < 0 || (ls_ >> extra)) throw bad("the $PhysicalNames count is not a number");
    for (long long k = 0; k < count; ++k) {
      long long dim = 2, tag = 0;
      read_line("$PhysicalNames");
      if (version_ > 2.0 && !(ls_ >> dim)) throw bad("a physical name's dimension is not a number");
      if (dim < 0 || dim > 3) throw bad(fmt::format("a physical name has dimension {}, not 0 to 3", dim));
      if (!(ls_ >> tag) || tag < -2147483647 || tag > 2147483647) throw bad("a physical name's tag is not an integer");
      std::string name;
      std::getline(ls_ >> std::ws, name);
      if (name.size() < 2 || name.front() != '"' || name.find('"', 1) == std::string::npos)
        throw bad("a physical name is not in double quotes");
    }
  }

  // $Entities (MSH 4.1): `points curves surfaces volumes`, then one line per entity: its tag, its box (x y z for a
  // point, two corners otherwise), its physical tags and, above points, its bounding entities, each list after its
  // length. gmsh 4.8 allocates a line buffer of 128 bytes per declared entity before it reads one, so a count that
  // the lines do not hold made it allocate 1.6 GB from a file of 263 bytes (found by tests/fuzz/fuzz_msh); it
  // reads the lists from the rest of the entity's line.
  void scan_entities() {
    read_line("$Entities");
    std::array<long long, 4> declared{};
    if (!(ls_ >> declared[0] >> declared[1] >> declared[2] >> declared[3]) || !at_end(ls_) ||
        *std::min_element(declared.begin(), declared.end()) < 0)
      throw bad("the $Entities header is not `points curves surfaces volumes`");
    constexpr long long kMostEntities = 1000000;
    long long total = 0;
    for (long long n : declared) total += std::min(n, kMostEntities + 1);  // no overflow
    if (total > kMostEntities)
      throw bad(fmt::format("the $Entities header declares {} {} {} {} entities, more than the {} rbdem reads",
                            declared[0], declared[1], declared[2], declared[3], kMostEntities));
    for (int dim = 0; dim < 4; ++dim)
      for (long long k = 0; k < declared[dim]; ++k) {
        read_line("$Entities");
        if (!entity_line(dim))
          throw bad(fmt::format("entity line {} of dimension {} is not `tag {} physicals{}`", k + 1, dim,
                                dim == 0 ? "x y z" : "min-x min-y min-z max-x max-y max-z",
                                dim == 0 ? "" : " bounding-entities"));
      }
  }

  // One entity line of dimension `dim` in ls_: the tag, the box and each list with exactly its length.
  bool entity_line(int dim) {
    long long tag = 0;
    if (!(ls_ >> tag) || tag < -2147483647 || tag > 2147483647) return false;
    double box = 0;
    for (int k = 0; k < (dim == 0 ? 3 : 6); ++k)
      if (!(ls_ >> box)) return false;
    for (int list = 0; list < (dim == 0 ? 1 : 2); ++list) {
      long long length = 0, item = 0;
      if (!(ls_ >> length) || length < 0 || length > 1000) return false;
      for (long long k = 0; k < length; ++k)
        if (!(ls_ >> item) || item < -2147483647 || item > 2147483647) return false;
    }
    return at_end(ls_);
  }

  // $Nodes: the header's counts and tags against the blocks, each node line exactly its numbers.
  void scan_nodes() {
    Counts header;
    read_line("$Nodes");
    if (!header.read(ls_, v4_)) throw bad("the $Nodes header is not `blocks nodes min-tag max-tag`");
    Counts found;
    for (long long b = 0; b < header.blocks; ++b) {
      long long n = header.count;
      if (v4_) {
        long long dim = 0, tag = 0, parametric = 0;
        read_line("$Nodes");
        if (!(ls_ >> dim >> tag >> parametric >> n) || n < 0 || !at_end(ls_))
          throw bad("a node block header is not `dim entity parametric nodes`");
        if (parametric != 0)
          throw SceneError(fmt::format("mesh file '{}' stores parametric node coordinates, which rbdem does not "
                                       "read: export it again with `Mesh.SaveParametric = 0;`",
                                       path_.string()));
      }
      for (long long k = 0; k < n; ++k) {
        long long tag = 0;
        read_line("$Nodes");
        if (!(ls_ >> tag) || tag < 1) throw bad("a node tag is not a positive integer");
        const int rest = count_numbers(ls_);
        if (v4_ ? rest != 0 : rest != 3)
          throw bad(fmt::format("the line of node {} does not hold exactly {}", tag,
                                v4_ ? "its tag" : "its tag and x y z"));
        nodes_.insert(tag);
        found.add(tag);
      }
      if (v4_)
        for (long long k = 0; k < n; ++k) {
          read_line("$Nodes");
          if (count_numbers(ls_) != 3) throw bad("a node coordinate line does not hold exactly x y z");
        }
    }
    header.require_match(found, "node", [this](const std::string& what) { return bad(what); });
  }

  // $Elements: the header's counts and tags against the blocks, every element of a known type with its number of
  // nodes, all of them defined in $Nodes.
  void scan_elements() {
    Counts header;
    read_line("$Elements");
    if (!header.read(ls_, v4_)) throw bad("the $Elements header is not `blocks elements min-tag max-tag`");
    Counts found;
    for (long long b = 0; b < header.blocks; ++b) {
      long long n = header.count;
      int type = 0;
      if (v4_) {
        long long dim = 0, tag = 0;
        read_line("$Elements");
        if (!(ls_ >> dim >> tag >> type >> n) || n < 0 || !at_end(ls_))
          throw bad("an element block header is not `dim entity type elements`");
      }
      for (long long k = 0; k < n; ++k) {
        long long tag = 0;
        read_line("$Elements");
        if (!(ls_ >> tag) || tag < 1) throw bad("an element tag is not a positive integer");
        found.add(tag);
        if (!v4_) {
          int ntags = 0;
          if (!(ls_ >> type >> ntags) || ntags < 0) throw bad(fmt::format("element {} has no type", tag));
          for (long long t = 0, skip = 0; t < ntags; ++t)
            if (!(ls_ >> skip)) throw bad(fmt::format("element {} has fewer tags than it says", tag));
        }
        check_element_nodes(tag, type);
      }
    }
    header.require_match(found, "element", [this](const std::string& what) { return bad(what); });
  }

  // The rest of an element's line: as many nodes as its type has, each defined in $Nodes.
  void check_element_nodes(long long tag, int type) {
    const int expected = nodes_of_type(type);
    if (expected < 0)
      throw SceneError(fmt::format("mesh file '{}': element {} has gmsh type {}, which rbdem does not read: use "
                                   "first-order triangles (type 2)",
                                   path_.string(), tag, type));
    int found_nodes = 0;
    for (long long node = 0; ls_ >> node; ++found_nodes)
      if (!nodes_.count(node))
        throw SceneError(fmt::format("mesh file '{}': element {} refers to node {}, which the file does not "
                                     "define; export the mesh from gmsh again",
                                     path_.string(), tag, node));
    if (found_nodes != expected)
      throw bad(fmt::format("element {} of type {} has {} nodes instead of {}", tag, type, found_nodes, expected));
  }

  const std::filesystem::path& path_;
  std::ifstream in_;
  std::string line_;         // the line last read
  std::istringstream ls_;    // line_, for the section scans to read from
  double version_ = 0;       // of $MeshFormat
  bool v4_ = false;          // MSH 4.1 (else 2.x)
  std::set<long long> nodes_;  // the node tags of $Nodes
};

// Checks that the file is ASCII MSH 2.x or 4.1, that its headers declare what follows and that every element has
// the right number of nodes and refers only to nodes the file defines. gmsh 4.8 dereferences a missing node of a
// second-order element and crashes (found by tests/fuzz/fuzz_msh), so rbdem checks this before gmsh reads the file;
// binary and MSH 3 files are refused.
void prescan_msh(const std::filesystem::path& path) {
  MshPrescan(path).run();
}

// Distinct nodes at the same place (within `tol`): the triangles around them look adjacent but share no edge, so no
// bond would join them. Nodes are hashed into cells of size tol; a duplicate lies in the same or a neighbouring cell.
void refuse_duplicate_nodes(const TriMesh& mesh, double tol, const std::string& source) {
  if (!(tol > 0)) return;
  const double x0 = mesh.nodes.empty() ? 0.0 : mesh.nodes[0][0], y0 = mesh.nodes.empty() ? 0.0 : mesh.nodes[0][1];
  auto cell_of = [&](const std::array<double, 2>& p) {
    return std::pair<long, long>{long(std::floor((p[0] - x0) / tol)), long(std::floor((p[1] - y0) / tol))};
  };
  std::map<std::pair<long, long>, std::vector<int>> grid;
  for (std::size_t k = 0; k < mesh.nodes.size(); ++k) {
    const auto& p = mesh.nodes[k];
    const auto [ci, cj] = cell_of(p);
    for (long i = ci - 1; i <= ci + 1; ++i)
      for (long j = cj - 1; j <= cj + 1; ++j) {
        auto it = grid.find({i, j});
        if (it == grid.end()) continue;
        for (int other : it->second) {
          const auto& q = mesh.nodes[other];
          if (std::abs(q[0] - p[0]) <= tol && std::abs(q[1] - p[1]) <= tol)
            throw SceneError(fmt::format("mesh file '{}': two nodes at ({:.6g}, {:.6g}) m: the triangles around them "
                                         "share no edge and would not be bonded; merge duplicate nodes (gmsh: "
                                         "Tools > Coherence Mesh, or `Coherence Mesh;` in the .geo) and save again",
                                         source, p[0], p[1]));
        }
      }
    grid[{ci, cj}].push_back(int(k));
  }
}

// A node inside an edge that only one triangle holds (a hanging node, T-junction): the mesh is not conforming and
// the blocks on either side of that edge would not be bonded. Nodes are binned in a grid of about one edge length.
void refuse_hanging_nodes(const TriMesh& mesh, double tol, const std::string& source) {
  std::map<std::pair<int, int>, int> uses;
  for (const auto& tri : mesh.triangles)
    for (int e = 0; e < 3; ++e) ++uses[std::minmax(tri[e], tri[(e + 1) % 3])];
  double xmin = 1e300, ymin = 1e300, xmax = -1e300, ymax = -1e300, edge_sum = 0;
  for (const auto& p : mesh.nodes) {
    xmin = std::min(xmin, p[0]), xmax = std::max(xmax, p[0]);
    ymin = std::min(ymin, p[1]), ymax = std::max(ymax, p[1]);
  }
  for (const auto& [edge, n] : uses) {
    const auto& a = mesh.nodes[edge.first];
    const auto& b = mesh.nodes[edge.second];
    edge_sum += std::hypot(b[0] - a[0], b[1] - a[1]);
  }
  const double cell = std::max(edge_sum / double(std::max<std::size_t>(uses.size(), 1)), 1e-300);
  const double span = std::max(xmax - xmin, ymax - ymin);
  // At most about 4 cells per node along each side keeps the grid small for any input.
  const double limit = 4.0 * std::sqrt(double(mesh.nodes.size())) + 1.0;
  const double h = std::max(cell, span / limit);
  auto cell_of = [&](double v, double lo) { return long(std::floor((v - lo) / h)); };
  std::map<std::pair<long, long>, std::vector<int>> grid;
  for (std::size_t k = 0; k < mesh.nodes.size(); ++k)
    grid[{cell_of(mesh.nodes[k][0], xmin), cell_of(mesh.nodes[k][1], ymin)}].push_back(int(k));
  for (const auto& [edge, n] : uses) {
    if (n != 1) continue;
    const auto& a = mesh.nodes[edge.first];
    const auto& b = mesh.nodes[edge.second];
    const double dx = b[0] - a[0], dy = b[1] - a[1], len2 = dx * dx + dy * dy;
    if (!(len2 > 0)) continue;
    const long i0 = cell_of(std::min(a[0], b[0]) - tol, xmin), i1 = cell_of(std::max(a[0], b[0]) + tol, xmin);
    const long j0 = cell_of(std::min(a[1], b[1]) - tol, ymin), j1 = cell_of(std::max(a[1], b[1]) + tol, ymin);
    const int ea = edge.first, eb = edge.second;  // clang 14 lambdas cannot capture structured bindings
    auto test = [&](int k) {
      if (k == ea || k == eb) return;
      const auto& p = mesh.nodes[k];
      const double t = ((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / len2;
      const double dist = std::abs((p[0] - a[0]) * dy - (p[1] - a[1]) * dx) / std::sqrt(len2);
      if (t > 0 && t < 1 && dist <= tol)
        throw SceneError(fmt::format(
                "mesh file '{}': node at ({:.6g}, {:.6g}) m lies inside the edge ({:.6g}, {:.6g})-({:.6g}, {:.6g}) m "
                "of a neighbouring triangle (a T-junction): the mesh is not conforming and those blocks would not be "
                "bonded; mesh all surfaces together so that they share nodes (gmsh: fragment the geometry, then "
                "mesh)",
                source, p[0], p[1], a[0], a[1], b[0], b[1]));
    };
    // A long edge over many cells: testing every node is cheaper than visiting the cells.
    if (double(i1 - i0 + 1) * double(j1 - j0 + 1) > double(mesh.nodes.size())) {
      for (std::size_t k = 0; k < mesh.nodes.size(); ++k) test(int(k));
      continue;
    }
    for (long i = i0; i <= i1; ++i)
      for (long j = j0; j <= j1; ++j)
        if (auto it = grid.find({i, j}); it != grid.end())
          for (int k : it->second) test(k);
  }
}

}  // namespace

void check_user_mesh(TriMesh& mesh, const std::string& source) {
  if (mesh.triangles.empty())
    throw SceneError(fmt::format("mesh file '{}' has no triangles in its physical surfaces", source));
  for (const auto& tri : mesh.triangles)
    for (int v : tri)
      if (v < 0 || std::size_t(v) >= mesh.nodes.size())
        throw SceneError(fmt::format("mesh file '{}': a triangle refers to node {} of {}", source, v,
                                     mesh.nodes.size()));
  double xmin = 1e300, ymin = 1e300, xmax = -1e300, ymax = -1e300;
  for (const auto& p : mesh.nodes) {
    if (!std::isfinite(p[0]) || !std::isfinite(p[1]))
      throw SceneError(fmt::format("mesh file '{}': a node has a non-finite coordinate ({}, {}); remesh",
                                   source, p[0], p[1]));
    xmin = std::min(xmin, p[0]), xmax = std::max(xmax, p[0]);
    ymin = std::min(ymin, p[1]), ymax = std::max(ymax, p[1]);
  }
  const double span = std::max(xmax - xmin, ymax - ymin);
  if (!std::isfinite(span))
    throw SceneError(fmt::format("mesh file '{}': node coordinates span more than 1e308 m; rbdem reads coordinates in "
                                 "metres: rescale the mesh",
                                 source));
  // Lengths below this are zero at the mesh's scale (coordinates carry about 16 digits).
  const double tol = 1e-9 * span;
  // Zero-area triangles are refused: a block without area has no mass. Clockwise triangles are turned
  // counter-clockwise (gmsh writes either orientation depending on the surface normal); noted, not refused.
  std::size_t reoriented = 0;
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& tri = mesh.triangles[t];
    const double a = signed_area(mesh, t);
    double longest = 0;
    for (int e = 0; e < 3; ++e) {
      const auto& p = mesh.nodes[tri[e]];
      const auto& q = mesh.nodes[tri[(e + 1) % 3]];
      longest = std::max(longest, std::hypot(q[0] - p[0], q[1] - p[1]));
    }
    // |a| = longest edge x height / 2: a height under tol is a triangle flattened onto a line.
    if (!(std::abs(a) > 0.5 * longest * tol))
      throw SceneError(fmt::format("mesh file '{}': triangle {} (nodes ({:.6g}, {:.6g}), ({:.6g}, {:.6g}), "
                                   "({:.6g}, {:.6g}) m) is degenerate (zero area); remove it or remesh",
                                   source, t, mesh.nodes[tri[0]][0], mesh.nodes[tri[0]][1],
                                   mesh.nodes[tri[1]][0], mesh.nodes[tri[1]][1], mesh.nodes[tri[2]][0],
                                   mesh.nodes[tri[2]][1]));
    if (a < 0) {
      std::swap(mesh.triangles[t][1], mesh.triangles[t][2]);
      ++reoriented;
    }
  }
  if (reoriented > 0)
    mesh.notes.push_back(fmt::format("{} clockwise triangles of {} turned counter-clockwise", reoriented,
                                     source));
  refuse_duplicate_nodes(mesh, tol, source);
  refuse_hanging_nodes(mesh, tol, source);
}

TriMesh read_msh(const std::filesystem::path& path) {
  if (!std::filesystem::exists(path))
    throw SceneError(fmt::format("mesh file '{}' does not exist: check --mesh / mesh.file", path.string()));
  require_msh_header(path);
  prescan_msh(path);
  TriMesh mesh = gmsh_io::read_with_gmsh(path);
  check_user_mesh(mesh, path.string());
  return mesh;
}

}  // namespace rbdem
