// What a 3D run reports above the engine: each crack's dip and dip direction against the joint sets' own
// convention (theory/elasticity3.hpp, plane_axes), the crack rose, the crack band's plane, the fragments' volumes,
// the volumetric strain eps_a + 2 eps_l and the crack damage stress it gives, the failure classification reading 3D
// normals; then a small jointed cylinder through run_case and every file of its run folder.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>
#include <stdexcept>

#include <unistd.h>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "dem/driver/signals.hpp"
#include "dem/driver/summary.hpp"
#include "io/run_case.hpp"
#include "theory/elasticity3.hpp"

namespace rbdem {
namespace {

Crack crack_with_normal(const std::array<double, 3>& n, double size = 1.0) {
  Crack c;
  c.normal = n, c.size = size;
  return c;
}

std::array<double, 3> minus(const std::array<double, 3>& n) { return {-n[0], -n[1], -n[2]}; }

// A plane built by plane_axes(dip, dd) reads back as (dip, dd), whichever sign its normal has; a vertical plane's
// two dip directions fold into [0, 180) and a horizontal one's is 0. In the x-z section a plane of dip direction 0
// traces the 2D edge at the dip (the 2D specimen's slice).
TEST(Outputs3, CrackOrientationIsTheJointSetsConvention) {
  for (const double dip : {5.0, 30.0, 45.0, 60.0, 89.0})
    for (const double dd : {0.0, 45.0, 135.0, 200.0, 330.0}) {
      const auto n = theory::plane_axes(dip, dd).normal;
      for (const auto& m : {n, minus(n)}) {
        const PlaneOrientation o = plane_orientation_deg(m);
        EXPECT_NEAR(o.dip_deg, dip, 1e-9) << dip << " " << dd;
        EXPECT_NEAR(o.dip_direction_deg, dd, 1e-9) << dip << " " << dd;
      }
    }
  for (const double dd : {0.0, 90.0, 180.0, 270.0}) {
    const auto n = theory::plane_axes(90.0, dd).normal;
    for (const auto& m : {n, minus(n)}) {
      EXPECT_DOUBLE_EQ(plane_orientation_deg(m).dip_deg, 90.0);
      EXPECT_NEAR(plane_orientation_deg(m).dip_direction_deg, std::fmod(dd, 180.0), 1e-9) << dd;
    }
  }
  EXPECT_EQ(plane_orientation_deg({0, 0, -1}).dip_deg, 0.0);
  EXPECT_EQ(plane_orientation_deg({0, 0, -1}).dip_direction_deg, 0.0);
  const auto n = theory::plane_axes(35.0, 0.0).normal;
  EXPECT_NEAR(edge_orientation_deg(n[0], n[2]), 35.0, 1e-9);
}

// The rose counts each crack once, in the bin of its dip and of its dip direction, and sums the face areas per dip.
TEST(Outputs3, CrackRoseCountsByDipAndDipDirection) {
  std::vector<Crack> cracks;
  cracks.push_back(crack_with_normal(theory::plane_axes(60.0, 10.0).normal, 2.0));   // dip bin 6, dd bin 0
  cracks.push_back(crack_with_normal(minus(theory::plane_axes(65.0, 20.0).normal)));  // 6, 0
  cracks.push_back(crack_with_normal(theory::plane_axes(62.0, 100.0).normal));        // 6, 3
  cracks.push_back(crack_with_normal(theory::plane_axes(90.0, 250.0).normal));        // 8 (90: the last), 70 -> 2
  cracks.push_back(crack_with_normal({0, 0, 1}, 0.5));                                // 0, 0
  // The faces of one plane on a bin's edge share the bin above, whatever their round-off.
  for (const double wobble : {-1e-12, 0.0, 1e-12}) {
    const auto n = theory::plane_axes(30.0, 0.0).normal;
    cracks.push_back(crack_with_normal({n[0] + wobble, n[1] - wobble, n[2] - wobble}));  // 3, 0
  }
  const CrackRose rose = crack_rose3(cracks);
  ASSERT_EQ(rose.by_dip.size(), 9u);
  ASSERT_EQ(rose.counts.size(), 9u);
  ASSERT_EQ(rose.counts[0].size(), 12u);
  EXPECT_EQ(rose.total(), 8);
  EXPECT_EQ(rose.by_dip[3], 3);
  EXPECT_EQ(rose.counts[3][0], 3);
  EXPECT_EQ(rose.by_dip[6], 3);
  EXPECT_EQ(rose.counts[6][0], 2);
  EXPECT_EQ(rose.counts[6][3], 1);
  EXPECT_EQ(rose.counts[8][2], 1);
  EXPECT_EQ(rose.counts[0][0], 1);
  EXPECT_DOUBLE_EQ(rose.area_by_dip[6], 4.0);
  EXPECT_DOUBLE_EQ(rose.area_by_dip[0], 0.5);
  EXPECT_EQ(crack_rose3({}).total(), 0);
  EXPECT_THROW(crack_rose3(cracks, 7.0), std::invalid_argument);
  EXPECT_THROW(crack_rose3(cracks, 10.0, 0.0), std::invalid_argument);
}

// Cracks scattered over one plane (dip 50, dip direction 120) around a point: the band's plane is that plane. Over
// a vertical plane (axial splitting) the band dips 90.
TEST(Outputs3, CrackBandIsThePlaneThroughTheCracks) {
  for (const auto& [dip, dd] : {std::pair{50.0, 120.0}, std::pair{90.0, 30.0}, std::pair{20.0, 300.0}}) {
    const theory::PlaneAxes axes = theory::plane_axes(dip, dd);
    const auto& n = axes.normal;
    const auto& s = axes.strike;
    const std::array<double, 3> up = {n[1] * s[2] - n[2] * s[1], n[2] * s[0] - n[0] * s[2], n[0] * s[1] - n[1] * s[0]};
    std::vector<Crack> cracks;
    for (int a = -3; a <= 3; ++a)
      for (int b = -2; b <= 2; ++b) {
        Crack c;
        for (std::size_t k = 0; k < 3; ++k) c.position[k] = 0.05 + 0.004 * a * s[k] + 0.006 * b * up[k];
        c.size = 1.0 + 0.1 * (a + 3);
        cracks.push_back(c);
      }
    const PlaneOrientation band = crack_band_plane(cracks);
    EXPECT_NEAR(band.dip_deg, dip, 1e-6) << dip << " " << dd;
    EXPECT_NEAR(band.dip_direction_deg, std::fmod(dd, dip == 90.0 ? 180.0 : 360.0), 1e-6) << dip << " " << dd;
  }
  EXPECT_TRUE(std::isnan(crack_band_plane({Crack{}, Crack{}}).dip_deg));
}

// Four unit cubes' worth of blocks in a row along z: fragments sum volumes and their centroids have z.
TEST(Outputs3, FragmentsAreVolumes) {
  Specimen s;
  s.dim = 3;
  for (int b = 0; b < 4; ++b) {
    s.blocks.centroid.insert(s.blocks.centroid.end(), {0.5, 0.5, b + 0.5});
    s.blocks.measure.push_back(b == 3 ? 3.0 : 1.0);
    s.blocks.layer.push_back(0);
  }
  for (int b = 0; b < 3; ++b) s.bonds.i.push_back(b), s.bonds.j.push_back(b + 1);
  Crack c;
  c.bond = 1;  // between blocks 1 and 2
  const auto f = fragments(s, {c});
  ASSERT_EQ(f.size(), 2u);
  EXPECT_DOUBLE_EQ(f[0].measure, 4.0);  // {2, 3}: 1 + 3
  EXPECT_DOUBLE_EQ(f[0].cz, (2.5 * 1.0 + 3.5 * 3.0) / 4.0);
  EXPECT_DOUBLE_EQ(f[1].measure, 2.0);
  EXPECT_DOUBLE_EQ(f[1].cz, 1.0);
}

// eps_l = -nu eps - k eps^2 under stress E eps: eps_v = eps (1 - 2 nu) - 2 k eps^2 in 3D turns at (1 - 2 nu) / (4 k),
// the plane-strain eps (1 - nu) - k eps^2 at (1 - nu) / (2 k). The crack damage stress of each dimension is E there.
TEST(Outputs3, VolumetricStrainIsAxialPlusTwiceTheRadialStrain) {
  CurvePoint p;
  p.strain = 1e-3, p.lateral_strain = -3e-4;
  EXPECT_DOUBLE_EQ(p.volumetric_strain(3), 4e-4);
  EXPECT_DOUBLE_EQ(p.volumetric_strain(2), 7e-4);
  const double E = 40e9, nu = 0.2, k = 300.0, peak_strain = 2e-3;  // both turns before the peak
  std::vector<CurvePoint> curve;
  for (int n = 0; n <= 2000; ++n) {
    CurvePoint q;
    q.strain = peak_strain * n / 2000.0;
    q.stress_top = q.stress_bottom = E * q.strain;
    q.lateral_strain = -nu * q.strain - k * q.strain * q.strain;
    curve.push_back(q);
  }
  const double step = E * peak_strain / 2000.0;
  EXPECT_NEAR(crack_damage_stress(curve, peak_strain, 3), E * (1 - 2 * nu) / (4 * k), step);
  EXPECT_NEAR(crack_damage_stress(curve, peak_strain, 2), E * (1 - nu) / (2 * k), step);
}

// A 3D specimen of three layers between two parallel joint planes dipping 45 deg (four faces each): one face of each
// plane broken in shear is no joint broken through (a quarter of each plane), hence no slip; every face of one
// plane in shear is slip along the joints. A reading of the normals' x and y only (the 2D one) takes each face of a
// plane for its own joint.
TEST(Outputs3, ClassificationGroupsTheFacesOfEachJointPlane) {
  Specimen s;
  s.dim = 3;
  s.lo = {0, 0, 0}, s.hi = {0.05, 0.05, 0.1};
  s.interface_names = {"joints"};
  s.blocks.layer = {0, 1, 1, 2};
  const auto n = theory::plane_axes(45.0, 0.0).normal;
  for (int plane = 0; plane < 2; ++plane)
    for (int f = 0; f < 4; ++f) {
      const double r = plane == 0 ? -0.01 : 0.01;  // n . (x - centre)
      const std::array<double, 3> along = {0.01 * (f % 2) * 0.7071, 0.01 * (f / 2), 0.01 * (f % 2) * 0.7071};
      s.bonds.i.push_back(plane == 0 ? 0 : 2), s.bonds.j.push_back(plane == 0 ? 1 : 3);
      s.bonds.kind.push_back(BondKind::joint), s.bonds.interface.push_back(0), s.bonds.material.push_back(1);
      s.bonds.size.push_back(1e-4);
      for (int k = 0; k < 3; ++k) {
        s.bonds.midpoint.push_back(s.centre(k) + r * n[std::size_t(k)] + along[std::size_t(k)]);
        s.bonds.normal.push_back((f % 2 ? -1.0 : 1.0) * n[std::size_t(k)]);  // either sign, as the mesh has it
      }
    }
  auto shear = [](int bond) {
    Crack c;
    c.bond = bond, c.kind = BondKind::joint, c.mode = BreakMode::shear;
    return c;
  };
  EXPECT_EQ(classify_failure({shear(0), shear(4)}, s, 45.0), "splitting_across_layers");
  EXPECT_EQ(classify_failure({shear(4), shear(5), shear(6), shear(7)}, s, 45.0), "shear_slip_along_joints");
  EXPECT_NEAR(joint_dip_deg(s, 0.0), 45.0, 1e-9);
}

std::string read_text(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::vector<std::vector<std::string>> read_csv(const std::filesystem::path& p) {
  std::vector<std::vector<std::string>> rows;
  std::ifstream in(p);
  for (std::string line; std::getline(in, line);) {
    std::vector<std::string> row;
    std::stringstream ls(line);
    for (std::string cell; std::getline(ls, cell, ',');) row.push_back(cell);
    rows.push_back(row);
  }
  return rows;
}

std::size_t column(const std::vector<std::string>& header, const std::string& name) {
  for (std::size_t k = 0; k < header.size(); ++k)
    if (header[k] == name) return k;
  ADD_FAILURE() << "no column " << name;
  return 0;
}

// A jointed cylinder (10 mm tetrahedra) to failure through run_case, into a fresh folder.
io::CaseRun cylinder_run(const std::filesystem::path& dir) {
  Scene scene;
  scene.specimen.dimension = 3;
  scene.mesh.size = 0.01;
  scene.joint_set.dip_deg = 60;
  scene.numerics.threads = 2;
  std::filesystem::remove_all(dir);
  io::CaseOptions o;
  o.out = dir;
  o.run.curve_points = 200;
  return io::run_case("ucs", scene, o);
}

// summary.json: the rose holds every crack, the band's plane, the fragments' volumes.
void check_summary(const std::filesystem::path& dir, const io::CaseRun& run) {
  const auto summary = nlohmann::json::parse(read_text(dir / "summary.json"));
  EXPECT_EQ(summary["dimension"], 3);
  EXPECT_EQ(summary["crack_rose"]["counts"].size(), 9u);
  int rose_total = 0;
  for (const auto& n : summary["crack_rose"]["by_dip"]) rose_total += n.get<int>();
  EXPECT_EQ(rose_total, int(run.result.cracks.size()));
  EXPECT_TRUE(summary["crack_band_dip_direction_deg"].is_number());
  EXPECT_GE(summary["crack_band_angle_deg"].get<double>(), 0.0);
  EXPECT_LE(summary["crack_band_angle_deg"].get<double>(), 90.0);
  EXPECT_FALSE(summary["fragments"].contains("largest_area_m2"));
  // Fragments: volumes that add up to the specimen's blocks.
  const auto frag = read_csv(dir / "fragments.csv");
  ASSERT_GE(frag.size(), 2u);
  const std::size_t vol = column(frag[0], "volume_m3");
  EXPECT_EQ(frag[0].back(), "z_m");
  double total = 0, blocks = 0;
  for (std::size_t k = 1; k < frag.size(); ++k) total += std::stod(frag[k][vol]);
  for (const double v : run.specimen.blocks.measure) blocks += v;
  EXPECT_NEAR(total / blocks, 1.0, 1e-6);
  EXPECT_NEAR(summary["fragments"]["largest_volume_m3"].get<double>(), std::stod(frag[1][vol]), 1e-6 * blocks);
}

// cracks.csv: the dip and dip direction of each crack's own normal; curve.csv: eps_v = eps_a + 2 eps_l.
void check_csv(const std::filesystem::path& dir) {
  const auto cracks = read_csv(dir / "cracks.csv");
  const auto& h = cracks[0];
  for (std::size_t k = 1; k < cracks.size(); ++k) {
    const auto o = plane_orientation_deg({std::stod(cracks[k][column(h, "normal_x")]),
                                          std::stod(cracks[k][column(h, "normal_y")]),
                                          std::stod(cracks[k][column(h, "normal_z")])});
    EXPECT_NEAR(std::stod(cracks[k][column(h, "dip_deg")]), o.dip_deg, 1e-3);
    const double dd = std::stod(cracks[k][column(h, "dip_direction_deg")]);
    EXPECT_NEAR(std::remainder(dd - o.dip_direction_deg, 360.0), 0.0, 1e-3);
    EXPECT_GE(dd, 0.0);
    EXPECT_LT(dd, 360.0);
  }
  const auto curve = read_csv(dir / "curve.csv");
  const std::size_t a = column(curve[0], "strain"), l = column(curve[0], "lateral_strain"),
                    v = column(curve[0], "volumetric_strain");
  for (std::size_t k = 1; k < curve.size(); ++k)
    EXPECT_NEAR(std::stod(curve[k][v]), std::stod(curve[k][a]) + 2 * std::stod(curve[k][l]), 1e-8);
}

const char* python = "/usr/bin/python3";

// result.xdmf: tetrahedra of four vertices and the rotation angle as a cell scalar, and valid XML; the figure
// script draws the 3D run's figures (the crack map as the x-z section).
void check_xdmf_and_figures(const std::filesystem::path& dir, std::size_t blocks) {
  const std::string xdmf = read_text(dir / "result.xdmf");
  EXPECT_NE(xdmf.find("TopologyType=\"Tetrahedron\""), std::string::npos);
  EXPECT_NE(xdmf.find(fmt::format("Dimensions=\"{} 4\"", blocks)), std::string::npos);
  EXPECT_NE(xdmf.find("/rotation_angle</DataItem>"), std::string::npos);
  const std::string probe = std::string(python) + " -c 'import matplotlib, h5py, numpy' > /dev/null 2>&1";
  if (!std::filesystem::exists(python) || std::system(probe.c_str()) != 0) return;  // no figure modules here
  const std::string xml = std::string(python) + " -c 'import sys, xml.etree.ElementTree as E; "
                                                "assert E.parse(sys.argv[1]).getroot().tag == \"Xdmf\"' '" +
                          (dir / "result.xdmf").string() + "'";
  EXPECT_EQ(std::system(xml.c_str()), 0);
  const auto script = std::filesystem::path(RBDEM_SOURCE_DIR) / "python" / "rbdem_figures.py";
  for (const char* figure : {"cracks", "stages", "rose", "fragments"}) {
    const auto png = dir / (std::string(figure) + ".png");
    const std::string cmd = fmt::format("{} '{}' {} '{}' '{}' > '{}' 2>&1", python, script.string(), figure,
                                        png.string(), dir.string(), (dir / "figures.log").string());
    EXPECT_EQ(std::system(cmd.c_str()), 0) << figure << ": " << read_text(dir / "figures.log");
    EXPECT_TRUE(std::filesystem::exists(png) && std::filesystem::file_size(png) > 1000) << png;
  }
}

TEST(Outputs3, UcsRunFolderOfACylinder) {
  const auto dir = std::filesystem::temp_directory_path() / fmt::format("rbdem_test_outputs3_{}", ::getpid());
  const io::CaseRun run = cylinder_run(dir);
  const TestResult& r = run.result;
  ASSERT_TRUE(r.completed) << r.watchdog_message;
  ASSERT_GT(r.cracks.size(), 10u);
  check_summary(dir, run);
  check_csv(dir);
  // The cylinder widens under axial load: a positive Poisson's ratio below 0.5.
  EXPECT_GT(r.poisson_ratio_at_half_peak, 0.0);
  EXPECT_LT(r.poisson_ratio_at_half_peak, 0.5);
  check_xdmf_and_figures(dir, run.specimen.num_blocks());
  if (!HasFailure()) std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace rbdem
