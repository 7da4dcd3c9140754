// checkpoint.h5: write and read. See checkpoint.hpp; the layout is in docs/outputs.md.
//
// The simulation's state is its snapshot (dem/snapshot.hpp), written field by field; the driver's scalars walk
// TestRecord::scalars() (dem/driver/record.hpp) and its curve and frames walk the records' field tables
// (dem/records.hpp): a new field of the state, of a boundary component or of a record is stored and restored without
// touching this file.
#include "io/checkpoint.hpp"

#include <cstring>
#include <map>
#include <type_traits>
#include <variant>

#include "io/h5.hpp"
#include "io/record_h5.hpp"

namespace rbdem::io {

using namespace h5;

namespace {

constexpr int checkpoint_version = 8;  // 5: the snapshot of a Simulation (boundary components' own fields);
                                        // 6: the frames' force networks; 7: TestRecord::platen_velocity;
                                        // 8: the contacts' dilation (opening)

std::string frame_name(std::size_t k) { return fmt::format("{:05d}", k); }

// The group that holds the field `path` ("a/b/c": the groups a and a/b under `root`, made when first needed and kept
// in `made`), and the field's own name.
std::pair<hid_t, std::string> parent_of(const Writer& w, hid_t root, const std::string& path,
                                        std::map<std::string, Id>& made) {
  hid_t at = root;
  std::size_t start = 0;
  for (std::size_t slash = path.find('/'); slash != std::string::npos; slash = path.find('/', start)) {
    const std::string dir = path.substr(0, slash);
    auto it = made.find(dir);
    if (it == made.end()) it = made.emplace(dir, w.group(at, path.substr(start, slash - start))).first;
    at = it->second, start = slash + 1;
  }
  return {at, path.substr(start)};
}

void write_snapshot(const Writer& w, hid_t loc, const Snapshot& snap) {
  w.attribute(loc, "dim", std::int32_t(snap.dim));
  std::map<std::string, Id> groups;
  for (const Snapshot::Entry& e : snap.entries) {
    const auto [at, name] = parent_of(w, loc, e.name, groups);
    std::visit(
        [&, at = at, &name = name](const auto& v) {
          using T = std::decay_t<decltype(v)>;
          if constexpr (std::is_same_v<T, double>) w.attribute(at, name, v);
          else if constexpr (std::is_same_v<T, long>) w.attribute(at, name, std::int64_t(v));
          else if constexpr (std::is_same_v<T, int>) w.attribute(at, name, std::int32_t(v));
          else if constexpr (std::is_same_v<T, bool>) w.attribute(at, name, std::int32_t(v ? 1 : 0));
          else if constexpr (std::is_same_v<T, std::vector<double>> || std::is_same_v<T, std::vector<int>>)
            w.dataset(at, name, v);
          else if constexpr (std::is_same_v<T, std::vector<std::uint8_t>>)
            w.dataset(at, name, std::vector<std::int32_t>(v.begin(), v.end()));
          else w.dataset(at, name, std::vector<std::int64_t>(v.begin(), v.end()));
        },
        e.value);
    w.attribute(at, name + ".type", std::int32_t(e.value.index()));  // which alternative, to read it back
    w.attribute(at, name + ".extent", std::int32_t(e.extent));
  }
}

// The snapshot back: every field the group holds (by the type recorded beside it), and its subgroups'.
void read_group(const Reader& rd, hid_t loc, const std::string& prefix, Snapshot& snap);

void read_field(const Reader& rd, hid_t loc, const std::string& name, const std::string& full, Snapshot& snap) {
  const auto type = rd.attribute<std::int32_t>(loc, name + ".type");
  const auto extent = Extent(rd.attribute<std::int32_t>(loc, name + ".extent"));
  switch (type) {
    case 0: snap.add(full, extent, rd.attribute<double>(loc, name)); break;
    case 1: snap.add(full, extent, long(rd.attribute<std::int64_t>(loc, name))); break;
    case 2: snap.add(full, extent, int(rd.attribute<std::int32_t>(loc, name))); break;
    case 3: snap.add(full, extent, rd.attribute<std::int32_t>(loc, name) != 0); break;
    case 4: snap.add(full, extent, rd.dataset<double>(loc, name)); break;
    case 5: snap.add(full, extent, rd.dataset<std::int32_t>(loc, name)); break;
    case 6: {
      const auto v = rd.dataset<std::int32_t>(loc, name);
      snap.add(full, extent, std::vector<std::uint8_t>(v.begin(), v.end()));
      break;
    }
    case 7: {
      const auto v = rd.dataset<std::int64_t>(loc, name);
      snap.add(full, extent, std::vector<std::uint64_t>(v.begin(), v.end()));
      break;
    }
    default: throw std::runtime_error("a snapshot field of an unknown type: " + full);
  }
}

void read_group(const Reader& rd, hid_t loc, const std::string& prefix, Snapshot& snap) {
  // The fields are recorded by their ".type" attributes; the subgroups are walked in name order.
  std::vector<std::string> attrs, links;
  H5Aiterate2(loc, H5_INDEX_NAME, H5_ITER_INC, nullptr,
              [](hid_t, const char* name, const H5A_info_t*, void* data) -> herr_t {
                static_cast<std::vector<std::string>*>(data)->push_back(name);
                return 0;
              },
              &attrs);
  H5Literate(loc, H5_INDEX_NAME, H5_ITER_INC, nullptr,
             [](hid_t g, const char* name, const H5L_info_t*, void* data) -> herr_t {
               const hid_t object = H5Oopen(g, name, H5P_DEFAULT);
               if (object >= 0 && H5Iget_type(object) == H5I_GROUP)
                 static_cast<std::vector<std::string>*>(data)->push_back(name);
               if (object >= 0) H5Oclose(object);
               return 0;
             },
             &links);
  const std::string suffix = ".type";
  for (const std::string& a : attrs)
    if (a.size() > suffix.size() && a.compare(a.size() - suffix.size(), suffix.size(), suffix) == 0) {
      const std::string name = a.substr(0, a.size() - suffix.size());
      read_field(rd, loc, name, prefix + name, snap);
    }
  for (const std::string& l : links) read_group(rd, rd.group(loc, l), prefix + l + "/", snap);
}

void write_frame(const Writer& w, hid_t loc, const std::string& name, const Frame& f) {
  const Id g = w.group(loc, name);
  write_attributes(w, g, f.dim, f);
  w.attribute(g, "dim", std::int32_t(f.dim));
  w.dataset(g, "pose", f.pose);
  const Id n = w.group(g, "network");
  w.dataset(n, "i", f.network.i), w.dataset(n, "j", f.network.j), w.dataset(n, "kind", f.network.kind);
  w.dataset(n, "force", f.network.force), w.dataset(n, "normal_force", f.network.normal_force);
}

Frame read_frame(const Reader& rd, hid_t loc, const std::string& name) {
  const Id g = rd.group(loc, name);
  Frame f;
  f.dim = rd.attribute<std::int32_t>(g, "dim");
  read_attributes(rd, g, f.dim, f);
  f.pose = rd.dataset<double>(g, "pose");
  const Id n = rd.group(g, "network");
  f.network.i = rd.dataset<std::int32_t>(n, "i"), f.network.j = rd.dataset<std::int32_t>(n, "j");
  f.network.kind = rd.dataset<std::uint8_t>(n, "kind");
  f.network.force = rd.dataset<float>(n, "force"), f.network.normal_force = rd.dataset<float>(n, "normal_force");
  return f;
}

// One scalar of the driver's record, written or read.
struct ScalarWriter {
  const Writer& w;
  hid_t g;
  void operator()(const char* name, double v) const { w.attribute(g, name, v); }
  void operator()(const char* name, long v) const { w.attribute(g, name, std::int64_t(v)); }
};
struct ScalarReader {
  const Reader& rd;
  hid_t g;
  void operator()(const char* name, double& v) const { v = rd.attribute<double>(g, name); }
  void operator()(const char* name, long& v) const { v = long(rd.attribute<std::int64_t>(g, name)); }
};

void write_checkpoint_file(const std::string& tmp, const TestCheckpoint& c) {
  const Writer w(tmp);
  Id file = w.create_file();
  w.attribute(file, "format", std::string("rbdem checkpoint"));
  w.attribute(file, "version", std::int32_t(checkpoint_version));
  w.attribute(file, "scene_toml", c.scene_toml);
  w.attribute(file, "test", c.test);
  write_snapshot(w, w.group(file, "state"), c.state);
  {
    const Id g = w.group(file, "driver");
    const TestRecord& r = c.record;
    const int dim = c.state.dim;
    r.scalars(ScalarWriter{w, g});
    write_table(w, w.group(g, "curve"), dim, r.curve, true);
    write_table(w, w.group(g, "at_peak"), dim, std::vector<CurvePoint>{r.at_peak}, true);
    write_frame(w, g, "peak_frame", r.peak_frame);
    const Id fg = w.group(g, "frames");
    w.attribute(fg, "count", std::int64_t(r.frames.size()));
    for (std::size_t k = 0; k < r.frames.size(); ++k) write_frame(w, fg, frame_name(k), r.frames[k]);
  }
  w.save(file);
}

TestCheckpoint read_checkpoint_file(const std::string& path) {
  const Reader rd(path);
  const Id file = rd.open_file();
  TestCheckpoint c;
  if (H5Aexists(file, "format") <= 0 || rd.attribute_string(file, "format") != "rbdem checkpoint")
    fail(path, "reading (not an rbdem checkpoint)");
  if (rd.attribute<std::int32_t>(file, "version") != checkpoint_version)
    fail(path, "reading (a checkpoint of another rbdem version: start afresh without --resume)");
  c.scene_toml = rd.attribute_string(file, "scene_toml");
  c.test = rd.attribute_string(file, "test");
  {
    const Id g = rd.group(file, "state");
    c.state.dim = rd.attribute<std::int32_t>(g, "dim");
    read_group(rd, g, "", c.state);
  }
  {
    const Id g = rd.group(file, "driver");
    TestRecord& r = c.record;
    const int dim = c.state.dim;
    r.scalars(ScalarReader{rd, g});
    r.curve = read_table<CurvePoint>(rd, rd.group(g, "curve"), dim, path);
    const auto at_peak = read_table<CurvePoint>(rd, rd.group(g, "at_peak"), dim, path);
    if (at_peak.size() != 1) fail(path, "reading the peak sample");
    r.at_peak = at_peak.front();
    r.peak_frame = read_frame(rd, g, "peak_frame");
    const Id fg = rd.group(g, "frames");
    const auto n = rd.attribute<std::int64_t>(fg, "count");
    for (std::int64_t k = 0; k < n; ++k) r.frames.push_back(read_frame(rd, fg, frame_name(std::size_t(k))));
  }
  return c;
}

}  // namespace

void write_checkpoint(const std::filesystem::path& path, const TestCheckpoint& c) {
  const std::lock_guard<std::mutex> guard(h5::lock());
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

TestCheckpoint read_checkpoint(const std::filesystem::path& path) {
  const std::lock_guard<std::mutex> guard(h5::lock());
  try {
    return read_checkpoint_file(path.string());
  } catch (const std::runtime_error& e) {
    throw std::runtime_error(fmt::format("cannot resume from {}: {}", path.string(), e.what()));
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(fmt::format("cannot resume from {}: {}", path.string(), e.what()));
  }
}

}  // namespace rbdem::io
