// checkpoint.h5: write and read. See checkpoint.hpp; the layout is in docs/outputs.md.
//
// The engine's state is written by walking ModelState::fields() (dem/state.hpp) and the driver's scalars by walking
// TestRecord::scalars() (dem/driver/record.hpp): a new state field is stored and restored without touching this
// file.
#include "io/checkpoint.hpp"

#include <cstring>
#include <type_traits>

#include "io/h5.hpp"

namespace rbdem::io {

using namespace h5;

namespace {

constexpr int checkpoint_version = 4;  // 4: the jacket (confining pressure), the lateral strain in the curve

std::string frame_name(std::size_t k) { return fmt::format("{:05d}", k); }

void write_curve(const Writer& w, hid_t loc, const std::string& name, const std::vector<CurvePoint>& curve) {
  const Id g = w.group(loc, name);
  std::vector<std::int64_t> step;
  std::vector<double> d;
  std::vector<std::int32_t> broken;
  for (const auto& p : curve) {
    step.push_back(p.step);
    d.insert(d.end(), {p.time, p.strain, p.stress_top, p.stress_bottom, p.kinetic, p.strain_energy, p.lateral_strain});
    broken.insert(broken.end(), p.broken.begin(), p.broken.end());
  }
  w.dataset(g, "step", step);
  w.dataset(g, "values", d.data(), {hsize_t(curve.size()), 7});
  w.dataset(g, "broken", broken.data(), {hsize_t(curve.size()), 4});
}

std::vector<CurvePoint> read_curve(const Reader& rd, hid_t loc, const std::string& name) {
  const Id g = rd.group(loc, name);
  const auto step = rd.dataset<std::int64_t>(g, "step");
  const auto d = rd.dataset<double>(g, "values");
  const auto broken = rd.dataset<std::int32_t>(g, "broken");
  std::vector<CurvePoint> curve(step.size());
  if (d.size() != 7 * step.size() || broken.size() != 4 * step.size()) throw std::runtime_error("bad curve " + name);
  for (std::size_t k = 0; k < curve.size(); ++k) {
    CurvePoint& p = curve[k];
    p.step = step[k];
    p.time = d[7 * k], p.strain = d[7 * k + 1], p.stress_top = d[7 * k + 2], p.stress_bottom = d[7 * k + 3];
    p.kinetic = d[7 * k + 4], p.strain_energy = d[7 * k + 5], p.lateral_strain = d[7 * k + 6];
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

// One field of the engine's state or the driver's record, written.
struct FieldWriter {
  const Writer& w;
  hid_t g;
  template <class T>
  void operator()(const char* name, const T& field, Extent = Extent::scalar, bool = false) const {
    if constexpr (std::is_same_v<T, double>) {
      w.attribute(g, name, field);
    } else if constexpr (std::is_same_v<T, long>) {
      w.attribute(g, name, std::int64_t(field));
    } else if constexpr (std::is_same_v<T, int>) {
      w.attribute(g, name, std::int32_t(field));
    } else if constexpr (std::is_same_v<T, bool>) {
      w.attribute(g, name, std::int32_t(field));
    } else if constexpr (std::is_same_v<T, std::vector<double>>) {
      w.dataset(g, name, field);
    } else if constexpr (std::is_same_v<T, std::vector<int>>) {
      w.dataset(g, name, field);
    } else if constexpr (std::is_same_v<T, std::vector<std::uint8_t>>) {
      w.dataset(g, name, std::vector<std::int32_t>(field.begin(), field.end()));
    } else if constexpr (std::is_same_v<T, ContactPairs>) {
      const Id cg = w.group(g, name);
      w.dataset(cg, "i", field.i);
      w.dataset(cg, "j", field.j);
      w.dataset(cg, "bond", field.bond);
      write_rows(w, cg, "law", field.law);
      w.dataset(cg, "fs", field.fs);
      w.dataset(cg, "fn", field.fn);
      w.dataset(cg, "chord", field.chord);
      w.dataset(cg, "key", std::vector<std::int64_t>(field.key.begin(), field.key.end()));
    } else if constexpr (std::is_same_v<T, std::vector<Crack>>) {
      const Id kg = w.group(g, name);
      std::vector<double> d;
      std::vector<std::int32_t> bond, kind, mode;
      for (const Crack& k : field) {
        d.insert(d.end(), {k.time, k.strain, k.x, k.y, k.sigma, k.tau});
        bond.push_back(k.bond), kind.push_back(int(k.kind)), mode.push_back(int(k.mode));
      }
      w.dataset(kg, "values", d.data(), {hsize_t(field.size()), 6});
      w.dataset(kg, "bond", bond);
      w.dataset(kg, "kind", kind);
      w.dataset(kg, "mode", mode);
    } else {
      static_assert(sizeof(T) == 0, "a state field of a type the checkpoint does not know");
    }
  }
};

// One field of the engine's state or the driver's record, read.
struct FieldReader {
  const Reader& rd;
  hid_t g;
  const std::string& path;
  template <class T>
  void operator()(const char* name, T& field, Extent = Extent::scalar, bool = false) const {
    if constexpr (std::is_same_v<T, double>) {
      field = rd.attribute<double>(g, name);
    } else if constexpr (std::is_same_v<T, long>) {
      field = long(rd.attribute<std::int64_t>(g, name));
    } else if constexpr (std::is_same_v<T, int>) {
      field = int(rd.attribute<std::int32_t>(g, name));
    } else if constexpr (std::is_same_v<T, bool>) {
      field = rd.attribute<std::int32_t>(g, name) != 0;
    } else if constexpr (std::is_same_v<T, std::vector<double>>) {
      field = rd.dataset<double>(g, name);
    } else if constexpr (std::is_same_v<T, std::vector<int>>) {
      field = rd.dataset<std::int32_t>(g, name);
    } else if constexpr (std::is_same_v<T, std::vector<std::uint8_t>>) {
      const auto v = rd.dataset<std::int32_t>(g, name);
      field.assign(v.begin(), v.end());
    } else if constexpr (std::is_same_v<T, ContactPairs>) {
      const Id cg = rd.group(g, name);
      field.i = rd.dataset<std::int32_t>(cg, "i");
      field.j = rd.dataset<std::int32_t>(cg, "j");
      field.bond = rd.dataset<std::int32_t>(cg, "bond");
      field.law = read_rows<LinearContact>(rd, cg, "law");
      field.fs = rd.dataset<double>(cg, "fs");
      field.fn = rd.dataset<double>(cg, "fn");
      field.chord = rd.dataset<double>(cg, "chord");
      const auto key = rd.dataset<std::int64_t>(cg, "key");
      field.key.assign(key.begin(), key.end());
    } else if constexpr (std::is_same_v<T, std::vector<Crack>>) {
      const Id kg = rd.group(g, name);
      const auto d = rd.dataset<double>(kg, "values");
      const auto bond = rd.dataset<std::int32_t>(kg, "bond");
      const auto kind = rd.dataset<std::int32_t>(kg, "kind");
      const auto mode = rd.dataset<std::int32_t>(kg, "mode");
      if (d.size() != 6 * bond.size() || kind.size() != bond.size() || mode.size() != bond.size())
        fail(path, "reading the crack log");
      field.clear();
      for (std::size_t k = 0; k < bond.size(); ++k) {
        Crack cr;
        cr.time = d[6 * k], cr.strain = d[6 * k + 1], cr.x = d[6 * k + 2], cr.y = d[6 * k + 3];
        cr.sigma = d[6 * k + 4], cr.tau = d[6 * k + 5];
        cr.bond = bond[k], cr.kind = BondKind(kind[k]), cr.mode = BreakMode(mode[k]);
        field.push_back(cr);
      }
    } else {
      static_assert(sizeof(T) == 0, "a state field of a type the checkpoint does not know");
    }
  }
};

void write_checkpoint_file(const std::string& tmp, const TestCheckpoint& c) {
  const Writer w(tmp);
  Id file = w.create_file();
  w.attribute(file, "format", std::string("rbdem checkpoint"));
  w.attribute(file, "version", std::int32_t(checkpoint_version));
  w.attribute(file, "scene_toml", c.scene_toml);
  w.attribute(file, "test", c.test);
  {
    const Id g = w.group(file, "engine");
    c.engine.fields(FieldWriter{w, g});
  }
  {
    const Id g = w.group(file, "driver");
    const TestRecord& r = c.record;
    r.scalars(FieldWriter{w, g});
    write_curve(w, g, "curve", r.curve);
    write_curve(w, g, "at_peak", {r.at_peak});
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
    const Id g = rd.group(file, "engine");
    c.engine.fields(FieldReader{rd, g, path});
  }
  {
    const Id g = rd.group(file, "driver");
    TestRecord& r = c.record;
    r.scalars(FieldReader{rd, g, path});
    r.curve = read_curve(rd, g, "curve");
    const auto at_peak = read_curve(rd, g, "at_peak");
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
  }
}

}  // namespace rbdem::io
