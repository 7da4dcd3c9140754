// rbdem mesh: mesh the specimen (or read --mesh), print its statistics, optionally write the .msh.
//
//   rbdem mesh --beta 30 --spacing 0.01 --out s.msh      # gmsh 4.1 file, one physical surface per layer
//   rbdem mesh --set mesh.size=0.0005                    # statistics only
//   rbdem mesh --set specimen.dimension=3                # the 3D cylinder's tetrahedral mesh, statistics only
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>

#include <fmt/format.h>

#include "apps/cli_common.hpp"
#include "apps/commands.hpp"
#include "dem/driver/summary.hpp"
#include "dem/materials.hpp"
#include "dem/specimen_mesh.hpp"
#include "dem/specimen_mesh3.hpp"
#include "dem/topology.hpp"

namespace rbdem::cli {

namespace {

struct MeshOptions {
  SceneOptions scene;
  std::string out;
};

void print_statistics(const Scene& scene, const TriMesh& mesh, const Topology<2>& topo, double seconds) {
  double amin = 1e300, amax = 0, lmin = 1e300;
  for (double a : topo.blocks.area) amin = std::min(amin, a), amax = std::max(amax, a);
  for (double l : topo.bonds.length) lmin = std::min(lmin, l);
  std::size_t boundary_by_side[5] = {0, 0, 0, 0, 0};
  for (auto s : topo.boundary.side) ++boundary_by_side[int(s)];
  fmt::print("specimen     {:.4g} m x {:.4g} m, joints {}\n", topo.width(), topo.height(),
             scene.joint_set.enabled && scene.mesh.file.empty()
                 ? fmt::format("dip {:.4g} deg, spacing {:.4g} m, offset {:.4g} m", scene.joint_set.dip_deg,
                               scene.joint_set.spacing, scene.joint_set.offset)
                 : std::string(scene.mesh.file.empty() ? "none" : "from " + scene.mesh.file));
  if (scene.mesh.file.empty()) {
    fmt::print("mesh         {} nodes, {} triangles, {} layers, target size {:.4g} m, meshed in {:.3f} s\n",
               mesh.num_nodes(), mesh.num_triangles(), mesh.num_layers(), scene.mesh.size, seconds);
  } else {  // a user mesh: its own edge lengths (shared edges), not the scene's mesh.size
    double lmax = 0, lsum = 0;
    for (double l : topo.bonds.length) lmax = std::max(lmax, l), lsum += l;
    fmt::print("mesh         {} nodes, {} triangles, {} layers, inner edges {:.3g} .. {:.3g} m (mean {:.3g} m), read "
               "in {:.3f} s\n",
               mesh.num_nodes(), mesh.num_triangles(), mesh.num_layers(), lmin, lmax,
               topo.bonds.size() ? lsum / double(topo.bonds.size()) : 0.0, seconds);
    const std::string warning = mesh_scale_warning(scene.mesh.file, std::max(topo.width(), topo.height()));
    if (!warning.empty()) fmt::print("warning      {}\n", warning);
  }
  fmt::print("blocks       {} (area {:.3g} .. {:.3g} m^2)\n", topo.blocks.size(), amin, amax);
  fmt::print("bonds        {} ({} rock, {} joint); joint length {:.6g} m; shortest edge {:.3g} m\n",
             topo.bonds.size(), topo.count(BondKind::rock), topo.count(BondKind::joint),
             topo.total_length(BondKind::joint), lmin);
  fmt::print("boundary     {} edges (bottom {}, right {}, top {}, left {}, other {})\n", topo.boundary.size(),
             boundary_by_side[0], boundary_by_side[1], boundary_by_side[2], boundary_by_side[3], boundary_by_side[4]);
  // Which material each bond got (dem/materials.hpp); throws SceneError for a group the mesh lacks.
  const MaterialMap materials = assign_materials(topo, scene);
  std::array<std::size_t, material_count> per_material{};
  for (auto m : materials.bond) ++per_material[m];
  std::string used;
  for (std::size_t m = 0; m < material_count; ++m)
    if (per_material[m]) used += fmt::format("{}{} {}", used.empty() ? "" : ", ", material_name[m], per_material[m]);
  fmt::print("materials    bonds: {}\n", used);
  if (uses_rock2(scene)) {  // which layers are rock2: by name, or by the beds' position at this dip
    const std::vector<std::uint8_t> rock2 = rock2_layers(topo, scene);
    std::string layers;
    for (std::size_t l = 0; l < rock2.size(); ++l)
      if (rock2[l])
        layers += fmt::format("{}{}", layers.empty() ? "" : ", ",
                              l < topo.layer_names.size() ? topo.layer_names[l] : std::to_string(l));
    fmt::print("rock2        layers {} of {}: {}\n", std::count(rock2.begin(), rock2.end(), 1), rock2.size(), layers);
  }
  if (!topo.interface_names.empty()) {
    std::string names;
    for (std::size_t f = 0; f < mesh.interfaces.size(); ++f)
      names += fmt::format("{}{} ({} edges)", f ? ", " : "", mesh.interfaces[f].name, mesh.interfaces[f].edges.size());
    fmt::print("interfaces   {}\n", names);
  }
  if (scene.joint_set2.enabled && scene.mesh.file.empty())
    fmt::print("joint set 2  dip {:.4g} deg, spacing {:.4g} m, offset {:.4g} m\n",
               second_set_dip_deg(scene, scene.joint_set.dip_deg), scene.joint_set2.spacing, scene.joint_set2.offset);
  for (const auto& note : mesh.notes) fmt::print("note         {}\n", note);
}

// A 3D scene: the tetrahedral mesh's counts (blocks = tetrahedra, bonds = shared faces) and its worst elements.
int run_mesh3(const Scene& scene, const MeshOptions& opt) {
  if (!opt.out.empty())
    throw SceneError(fmt::format("--out {}: writing the 3D mesh as .msh is not built; drop --out (rbdem mesh prints "
                                 "the 3D mesh's statistics)",
                                 opt.out));
  const SpecimenGeometry3 g = specimen_geometry3(scene);
  const TetMesh mesh = mesh_scene3(scene);
  const TetMeshReport r = report(mesh);
  if (!scene.mesh.file.empty())
    fmt::print("specimen     user mesh {}, {} layers: ", scene.mesh.file, mesh.num_layers());
  if (!scene.mesh.file.empty())
    for (std::size_t l = 0; l < mesh.num_layers(); ++l)
      fmt::print("{}{}", l ? ", " : "", mesh.layer_names[l]);
  else if (g.shape == Shape3::cylinder)
    fmt::print("specimen     cylinder {:.4g} m x {:.4g} m", g.diameter, g.height);
  else
    fmt::print("specimen     prism {:.4g} m x {:.4g} m x {:.4g} m", g.width, g.depth, g.height);
  if (!scene.mesh.file.empty())
    fmt::print("\n");
  else if (g.joints)
    fmt::print(", joints dip {:.4g} deg, dip direction {:.4g} deg, spacing {:.4g} m\n", g.set1.dip_deg,
               g.set1.dip_direction_deg, g.set1.spacing);
  else
    fmt::print(", no joints\n");
  if (scene.mesh.file.empty())
    fmt::print("mesh         {} nodes, {} tetrahedra, {} layers, target size {:.4g} m, meshed in {:.3f} s\n",
               r.nodes, r.tets, r.layers, scene.mesh.size, r.mesh_seconds);
  else
    fmt::print("mesh         {} nodes, {} tetrahedra, {} layers, read in {:.3f} s\n", r.nodes, r.tets, r.layers,
               r.mesh_seconds);
  if (scene.mesh.file.empty())
    fmt::print("blocks       {} (volume {:.6g} m^3 of {:.6g} m^3 ideal)\n", r.tets, r.volume, g.volume());
  else
    fmt::print("blocks       {} (volume {:.6g} m^3)\n", r.tets, r.volume);
  fmt::print("bonds        {} ({} rock, {} joint faces)\n", r.rock_faces + r.joint_faces, r.rock_faces,
             r.joint_faces);
  fmt::print("boundary     {} faces (bottom {}, top {}, side {})\n", r.bottom_faces + r.top_faces + r.lateral_faces,
             r.bottom_faces, r.top_faces, r.lateral_faces);
  fmt::print("quality      smallest dihedral angle {:.3g} deg, radius ratio {:.3g}, {} slivers (dihedral < {:g} "
             "deg)\n",
             r.min_dihedral_deg, r.min_radius_ratio, r.slivers, sliver_deg);
  for (const auto& note : mesh.notes) fmt::print("note         {}\n", note);
  return ok;
}

int run_mesh(const MeshOptions& opt) {
  const Scene scene = resolve_scene(opt.scene);
  print_scene(scene, opt.scene);
  if (scene.specimen.dimension == 3) return run_mesh3(scene, opt);
  const auto t0 = std::chrono::steady_clock::now();
  const TriMesh mesh = make_mesh(scene, opt.out);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const Topology<2> topo = build_topology(mesh, scene.specimen.thickness, scene.rock.density);
  print_statistics(scene, mesh, topo, seconds);
  if (!opt.out.empty()) {
    if (!scene.mesh.file.empty())
      fmt::print("note         --out ignored: the mesh was read from {}, not generated\n", scene.mesh.file);
    else
      fmt::print("wrote        {}\n", opt.out);
  }
  return ok;
}

}  // namespace

Runner add_mesh_command(CLI::App& app) {
  auto opt = std::make_shared<MeshOptions>();
  CLI::App* cmd = app.add_subcommand("mesh", "mesh the specimen and print block/bond statistics; --out writes .msh");
  add_scene_options(*cmd, opt->scene);
  cmd->add_option("--out,-o", opt->out, "write the mesh here (gmsh MSH 4.1, one physical surface per layer)");
  return [opt]() { return run_mesh(*opt); };
}

}  // namespace rbdem::cli
