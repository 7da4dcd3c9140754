// Result writers. See results.hpp.
#include "io/results.hpp"

#include "io/result_h5.hpp"
#include "dem/version.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <stdexcept>

#include <fmt/format.h>
#include <fmt/os.h>
#include <fmt/ranges.h>

#include "dem/record_columns.hpp"

namespace rbdem::io {

namespace {

// The keys of the headline numbers: null in the summary of a run that did not complete.
constexpr const char* measured_keys[] = {
    "peak_stress_pa", "strain_at_peak", "youngs_modulus_pa", "platen_force_mismatch",
    "platen_force_mismatch_at_peak", "kinetic_to_strain_energy_at_peak", "kinetic_to_strain_energy_loading",
    "crack_band_angle_deg", "tensile_fraction", "lateral_strain_at_peak", "poisson_ratio_at_half_peak",
    "crack_initiation_stress_pa", "crack_damage_stress_pa", "residual_stress_pa", "crack_initiation_to_peak",
    "crack_damage_to_peak", "residual_to_peak"};

// The signals (docs/theory.md, section 10): null where not defined.
void add_signals(nlohmann::json& j, const TestResult& r) {
  auto defined = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); };
  auto to_peak = [&](double v) {
    return std::isfinite(v) && r.peak_stress > 0 ? nlohmann::json(v / r.peak_stress) : nlohmann::json(nullptr);
  };
  j["poisson_ratio_at_half_peak"] = defined(r.poisson_ratio_at_half_peak);
  j["crack_initiation_stress_pa"] = defined(r.crack_initiation_stress);
  j["crack_damage_stress_pa"] = defined(r.crack_damage_stress);
  j["residual_stress_pa"] = defined(r.residual_stress);
  j["crack_initiation_to_peak"] = to_peak(r.crack_initiation_stress);
  j["crack_damage_to_peak"] = to_peak(r.crack_damage_stress);
  j["residual_to_peak"] = to_peak(r.residual_stress);
}

// A record table (dem/records.hpp) as a JSON array of objects, one key per field of its table; NaN as null.
template <class Record>
nlohmann::json record_array(int dim, const std::vector<Record>& rows) {
  nlohmann::json a = nlohmann::json::array();
  for (std::size_t k = 0; k < rows.size(); ++k) a.push_back(nlohmann::json::object());
  write_columns(dim, rows, [&](const Field& field, const auto& column, bool) {
    for (std::size_t k = 0; k < rows.size(); ++k) {
      using V = std::decay_t<decltype(column[k])>;
      if constexpr (std::is_floating_point_v<V>)
        a[k][field.name] = std::isfinite(column[k]) ? nlohmann::json(column[k]) : nlohmann::json(nullptr);
      else
        a[k][field.name] = column[k];
    }
  });
  return a;
}

void add_cracks(nlohmann::json& j, const TestResult& r) {
  j["cracks"] = {{"rock_tensile", r.crack_counts.rock_tensile},
                 {"rock_shear", r.crack_counts.rock_shear},
                 {"joint_tensile", r.crack_counts.joint_tensile},
                 {"joint_shear", r.crack_counts.joint_shear},
                 {"total", r.crack_counts.total()}};
  j["cracks_by_material"] = nlohmann::json::object();
  for (const auto& m : r.cracks_by_material)
    j["cracks_by_material"][m.material] = {{"bonds", m.bonds}, {"tensile", m.tensile}, {"shear", m.shear}};
  double total = 0;
  for (const auto& f : r.fragments) total += f.measure;
  const double largest = r.fragments.empty() ? 0.0 : r.fragments.front().measure;
  int single = 0;
  for (const auto& f : r.fragments) single += f.blocks == 1;
  // 3D: the fragments' sizes are volumes.
  const bool solid = r.dimension == 3;
  j["fragments"] = {{"count", r.fragments.size()},
                    {"single_blocks", single},
                    {solid ? "largest_volume_m3" : "largest_area_m2", largest},
                    {solid ? "largest_volume_fraction" : "largest_area_fraction", total > 0 ? largest / total : 0.0}};
}

// 3D: the crack band's dip direction and the crack rose (cracks by dip and dip direction); 2D runs write neither.
void add_orientations3(nlohmann::json& j, const TestResult& r) {
  if (r.dimension != 3) return;
  auto defined = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); };
  j["crack_band_angle_deg"] = defined(r.crack_band_angle_deg);
  j["crack_band_dip_direction_deg"] = defined(r.crack_band_dip_direction_deg);
  const CrackRose& rose = r.crack_rose;
  j["crack_rose"] = {{"dip_bin_deg", rose.dip_bin_deg},
                     {"dip_direction_bin_deg", rose.dip_direction_bin_deg},
                     {"by_dip", rose.by_dip},
                     {"area_by_dip_m2", rose.area_by_dip},
                     {"counts", rose.counts}};
}

}  // namespace

nlohmann::json run_summary(const Scene& scene, const TestResult& r) {
  nlohmann::json j;
  j["version"] = version_text();
  j["test"] = r.test;
  j["dimension"] = r.dimension;
  // A user mesh's joints dip as drawn: beta_deg is measured from them, and beta_source says so.
  const bool measured = !scene.mesh.file.empty() && std::isfinite(r.joint_dip_deg);
  j["beta_deg"] = measured ? r.joint_dip_deg : scene.joint_set.dip_deg;
  j["beta_source"] = measured ? "mesh" : "scene";
  if (r.dimension == 3)  // the planes' azimuth, in [0, 360) as the mesh has it
    j["beta_dip_direction_deg"] = std::fmod(scene.joint_set.dip_direction_deg + 720.0, 360.0);
  j["spacing_m"] = scene.joint_set.spacing;
  j["peak_stress_pa"] = r.peak_stress;
  j["strain_at_peak"] = r.strain_at_peak;
  j["youngs_modulus_pa"] = r.youngs_modulus;
  j["blocks"] = r.blocks;
  j["bonds"] = r.bonds;
  j["bonds_by_kind"] = {{"rock", r.rock_bonds}, {"joint", r.joint_bonds}};
  add_cracks(j, r);
  j["failure_mode"] = r.failure_mode;
  j["crack_band_angle_deg"] = r.crack_band_angle_deg;
  j["tensile_fraction"] = r.tensile_fraction;
  add_orientations3(j, r);
  j["stop_reason"] = r.stop_reason;
  j["steps"] = r.steps;
  j["dt_s"] = r.dt;
  j["dt_critical_s"] = r.dt_critical;
  j["dt_block_estimate_s"] = r.dt_block_estimate;
  j["mass_scaling"] = r.mass_scaling;
  j["elastic_start_strain"] = r.elastic_start_strain;
  j["platen_velocity_m_s"] = r.platen_velocity > 0.0 ? nlohmann::json(r.platen_velocity) : nlohmann::json(nullptr);
  j["wall_seconds"] = r.wall_seconds;
  j["threads"] = r.threads;
  j["platen_force_mismatch"] = r.platen_force_mismatch;
  j["platen_force_mismatch_at_peak"] = r.platen_force_mismatch_at_peak;
  j["kinetic_to_strain_energy_at_peak"] = r.kinetic_to_strain_at_peak;
  j["kinetic_to_strain_energy_loading"] = r.kinetic_to_strain_loading;
  j["quasi_static"] = r.quasi_static;
  j["quasi_static_reason"] = r.quasi_static_reason;
  j["energy_ratio_max"] = r.energy_ratio_max;
  j["confining_pressure_pa"] = r.confining_pressure;
  j["lateral_strain_at_peak"] = r.lateral_strain_at_peak;
  add_signals(j, r);
  for (const ResultValue& v : r.own) j[v.key] = v.value;  // the protocol's own numbers
  if (!r.cycles.empty()) j["cycles"] = record_array(r.dimension, r.cycles);
  j["completed"] = r.completed;
  j["watchdog"] = r.completed ? nlohmann::json(nullptr)
                              : nlohmann::json{{"cause", r.watchdog_cause},
                                               {"step", r.watchdog_step},
                                               {"message", r.watchdog_message}};
  if (!r.completed) {  // a broken run has no headline numbers: never a plausible value from it
    for (const char* key : measured_keys) j[key] = nullptr;
    if (r.dimension == 3) j["crack_band_dip_direction_deg"] = nullptr;
    for (const ResultValue& v : r.own)
      if (v.measured) j[v.key] = nullptr;
  }
  j["scene"] = scene_json(scene);
  return j;
}

void write_file_checked(const std::filesystem::path& file, const std::string& text) {
  const std::string name = file.string();
  const int fd = ::open(name.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0)
    throw std::runtime_error(fmt::format("cannot write {}: {}; check that the output folder is writable", name,
                                         std::strerror(errno)));
  const char* p = text.data();
  std::size_t left = text.size();
  int error = 0;
  while (left > 0) {
    const ssize_t n = ::write(fd, p, left);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      error = n < 0 ? errno : EIO;
      break;
    }
    p += n, left -= std::size_t(n);
  }
  // fsync: a full disk or quota can surface only when the data reach the device.
  if (!error && ::fsync(fd) != 0 && errno != EINVAL && errno != EROFS) error = errno;
  if (::close(fd) != 0 && !error) error = errno;
  if (error)
    throw std::runtime_error(fmt::format("writing {} failed after {} of {} bytes: {} (disk full?)", name,
                                         text.size() - left, text.size(), std::strerror(error)));
}

void require_writable_dir(const std::filesystem::path& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec)
    throw std::invalid_argument(fmt::format("cannot create the output folder {}: {}; choose another --out",
                                            dir.string(), ec.message()));
  const auto probe = dir / fmt::format(".rbdem-write-test-{}", ::getpid());  // one per process (MPI ranks)
  try {
    write_file_checked(probe, "rbdem\n");
  } catch (const std::exception& e) {
    std::filesystem::remove(probe, ec);
    throw std::invalid_argument(fmt::format("the output folder {} cannot be written ({}); choose another --out",
                                            dir.string(), e.what()));
  }
  std::filesystem::remove(probe, ec);
}

void write_text_atomic(const std::filesystem::path& file, const std::string& text) {
  const auto tmp = std::filesystem::path(file.string() + ".tmp");
  try {
    write_file_checked(tmp, text);
  } catch (...) {
    std::error_code ec;
    std::filesystem::remove(tmp, ec);  // never leave a half file behind; the previous version stays
    throw;
  }
  std::filesystem::rename(tmp, file);
}

namespace {

// One CSV cell of a field's value: doubles with the field's significant digits, the enumerations by name.
template <class V>
void append_cell(std::string& s, const V& v, int digits) {
  if constexpr (std::is_same_v<V, double>) fmt::format_to(std::back_inserter(s), "{:.{}g}", v, digits);
  else if constexpr (std::is_enum_v<V>) s += name_of(v);
  else fmt::format_to(std::back_inserter(s), "{}", v);
}

// The rows of a record table as CSV, one column per field of its table (dem/records.hpp), in its order.
template <class Record>
std::string csv_table(int dim, const std::vector<Record>& rows) {
  std::vector<std::string> header;
  std::vector<std::string> cells(rows.size());
  write_columns(dim, rows, [&](const Field& field, const auto& column, bool) {
    header.push_back(field.name);
    for (std::size_t k = 0; k < rows.size(); ++k) {
      if (header.size() > 1) cells[k] += ',';
      append_cell(cells[k], column[k], field.digits);
    }
  });
  std::string s = fmt::format("{}\n", fmt::join(header, ","));
  for (const auto& row : cells) s += row + "\n";
  return s;
}

}  // namespace

void write_curve_csv(const std::filesystem::path& file, int dim, const std::vector<CurvePoint>& curve) {
  write_text_atomic(file, csv_table(dim, curve));
}

void write_cracks_csv(const std::filesystem::path& file, int dim, const std::vector<Crack>& cracks) {
  write_text_atomic(file, csv_table(dim, cracks));
}

void write_fragments_csv(const std::filesystem::path& file, const std::vector<Fragment>& fragments, int dim) {
  double total = 0;
  for (const auto& f : fragments) total += f.measure;
  std::string s = dim == 3 ? "fragment,blocks,volume_m3,volume_fraction,x_m,y_m,z_m\n"
                           : "fragment,blocks,area_m2,area_fraction,x_m,y_m\n";
  for (std::size_t k = 0; k < fragments.size(); ++k) {
    const Fragment& f = fragments[k];
    s += fmt::format("{},{},{:.9g},{:.9g},{:.9g},{:.9g}", k, f.blocks, f.measure,
                     total > 0 ? f.measure / total : 0.0, f.cx, f.cy);
    s += dim == 3 ? fmt::format(",{:.9g}\n", f.cz) : std::string("\n");
  }
  write_text_atomic(file, s);
}

void write_crack_rate_csv(const std::filesystem::path& file, const std::vector<CrackRateBin>& bins) {
  std::string s = "strain_low,strain_high,cracks,crack_rate_per_strain\n";
  for (const auto& b : bins)
    s += fmt::format("{:.9g},{:.9g},{},{:.9g}\n", b.strain_low, b.strain_high, b.cracks, b.rate);
  write_text_atomic(file, s);
}

void write_run(const std::filesystem::path& dir, const Scene& scene, const Specimen& specimen, const TestResult& r,
               int threads) {
  std::filesystem::create_directories(dir);
  write_text_atomic(dir / "scene.toml", to_toml(scene));
  write_curve_csv(dir / "curve.csv", specimen.dim, r.curve);
  write_cracks_csv(dir / "cracks.csv", specimen.dim, r.cracks);
  write_fragments_csv(dir / "fragments.csv", r.fragments, specimen.dim);
  write_crack_rate_csv(dir / "crack_rate.csv", r.crack_rate);
  if (!r.cycles.empty()) write_text_atomic(dir / "cycles.csv", csv_table(specimen.dim, r.cycles));
  write_result_h5(dir / "result.h5", scene, specimen, r, threads);
  write_result_xdmf(dir / "result.xdmf", dir / "result.h5", specimen, r.test, r.frames);
  write_network_xdmf(dir / "forces.xdmf", dir / "result.h5", specimen, r.test, r.frames);
  write_text_atomic(dir / "summary.json", run_summary(scene, r).dump(2) + "\n");
}

}  // namespace rbdem::io
