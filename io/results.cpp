// Result writers. See results.hpp.
#include "io/results.hpp"

#include "io/result_h5.hpp"
#include "dem/version.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

#include <fmt/format.h>
#include <fmt/os.h>

namespace rbdem::io {

nlohmann::json run_summary(const Scene& scene, const TestResult& r) {
  nlohmann::json j;
  j["version"] = version_text();
  j["test"] = r.test;
  j["beta_deg"] = scene.joint_set.dip_deg;
  j["spacing_m"] = scene.joint_set.spacing;
  j["peak_stress_pa"] = r.peak_stress;
  j["strain_at_peak"] = r.strain_at_peak;
  j["youngs_modulus_pa"] = r.youngs_modulus;
  j["blocks"] = r.blocks;
  j["bonds"] = r.bonds;
  j["bonds_by_kind"] = {{"rock", r.rock_bonds}, {"joint", r.joint_bonds}};
  j["cracks"] = {{"rock_tensile", r.crack_counts.rock_tensile},
                 {"rock_shear", r.crack_counts.rock_shear},
                 {"joint_tensile", r.crack_counts.joint_tensile},
                 {"joint_shear", r.crack_counts.joint_shear},
                 {"total", r.crack_counts.total()}};
  j["failure_mode"] = r.failure_mode;
  j["crack_band_angle_deg"] = r.crack_band_angle_deg;
  j["tensile_fraction"] = r.tensile_fraction;
  j["stop_reason"] = r.stop_reason;
  j["steps"] = r.steps;
  j["dt_s"] = r.dt;
  j["dt_critical_s"] = r.dt_critical;
  j["dt_block_estimate_s"] = r.dt_block_estimate;
  j["mass_scaling"] = r.mass_scaling;
  j["elastic_start_strain"] = r.elastic_start_strain;
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
  if (r.test == "triaxial") {
    j["deviator_at_peak_pa"] = r.deviator_at_peak;
    j["axial_strain_at_peak"] = r.strain_at_peak;
    j["isotropic_strain"] = r.isotropic_strain;
    j["jacket_edges_lost"] = r.jacket_edges_lost;
  }
  if (r.test == "brazilian") {
    j["tensile_strength_pa"] = r.tensile_strength;
    j["peak_load_n"] = r.peak_load;
    j["layer_angle_deg"] = r.layer_angle_deg;
    j["diameter_m"] = r.diameter;
  }
  j["completed"] = r.completed;
  j["watchdog"] = r.completed ? nlohmann::json(nullptr)
                              : nlohmann::json{{"cause", r.watchdog_cause},
                                               {"step", r.watchdog_step},
                                               {"message", r.watchdog_message}};
  if (!r.completed)  // a broken run has no headline numbers: never a plausible value from it
    for (const char* key : {"peak_stress_pa", "strain_at_peak", "youngs_modulus_pa", "platen_force_mismatch",
                            "platen_force_mismatch_at_peak", "kinetic_to_strain_energy_at_peak",
                            "kinetic_to_strain_energy_loading", "crack_band_angle_deg", "tensile_fraction",
                            "lateral_strain_at_peak", "deviator_at_peak_pa", "axial_strain_at_peak",
                            "tensile_strength_pa", "peak_load_n"})
      if (j.contains(key)) j[key] = nullptr;
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

void write_curve_csv(const std::filesystem::path& file, const std::vector<CurvePoint>& curve) {
  std::string s =
      "step,time_s,strain,stress_top_pa,stress_bottom_pa,kinetic_j,strain_energy_j,"
      "broken_rock_tensile,broken_rock_shear,broken_joint_tensile,broken_joint_shear,lateral_strain\n";
  for (const auto& p : curve)
    s += fmt::format("{},{:.9g},{:.9g},{:.9g},{:.9g},{:.6g},{:.6g},{},{},{},{},{:.9g}\n", p.step, p.time, p.strain,
                     p.stress_top, p.stress_bottom, p.kinetic, p.strain_energy, p.broken[0], p.broken[1], p.broken[2],
                     p.broken[3], p.lateral_strain);
  write_text_atomic(file, s);
}

void write_cracks_csv(const std::filesystem::path& file, const std::vector<Crack>& cracks) {
  std::string s = "time_s,strain,x_m,y_m,kind,mode,bond,sigma_pa,tau_pa\n";
  for (const auto& c : cracks)
    s += fmt::format("{:.9g},{:.9g},{:.9g},{:.9g},{},{},{},{:.6g},{:.6g}\n", c.time, c.strain, c.x, c.y,
                     c.kind == BondKind::rock ? "rock" : "joint", c.mode == BreakMode::shear ? "shear" : "tensile",
                     c.bond, c.sigma, c.tau);
  write_text_atomic(file, s);
}

void write_run(const std::filesystem::path& dir, const Scene& scene, const TriMesh& mesh, const Topology& topo,
               const TestResult& r) {
  std::filesystem::create_directories(dir);
  write_text_atomic(dir / "scene.toml", to_toml(scene));
  write_curve_csv(dir / "curve.csv", r.curve);
  write_cracks_csv(dir / "cracks.csv", r.cracks);
  write_result_h5(dir / "result.h5", scene, mesh, topo, r);
  write_result_xdmf(dir / "result.xdmf", dir / "result.h5", topo.blocks.size(), r.frames);
  write_text_atomic(dir / "summary.json", run_summary(scene, r).dump(2) + "\n");
}

}  // namespace rbdem::io
