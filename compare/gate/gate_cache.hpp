// The elastic gate in front of failure runs (rbdem ucs, later rbdem sweep): run it once per elastic behaviour,
// remember the verdict, refuse a run whose DEM does not reproduce its own elastic theory.
//
// Cache key: a hash of every scene key that can change the elastic response, i.e. every key except
// joint_set.dip_deg (the gate runs every dip), the bond strengths of every material (tensile_strength, cohesion,
// friction_deg, moment_factor, fracture_energy, weibull_modulus, and mesh.strength_seed unless a material's
// stiffness_weibull_modulus draws stiffness factors from it), rock.density and
// rock2.density (statics see no mass), loading.* (the gate uses frictionless platens; the rest are stop criteria and
// speed), numerics.* (time integration) and output.*. Keys added to the scene later are in the
// key until listed here, so a stale verdict is never reused. A user mesh (mesh.file) enters with its contents.
// The key also holds a gate version string (gate_cache.cpp; 3 since its joints are unilateral), bumped
// when the measurement or the verdict changes meaning, and rbdem's version and commit (version_text()), so a
// verdict of another build is never reused.
// Cache folder: $RBDEM_CACHE_DIR, else $XDG_CACHE_HOME/rbdem, else $HOME/.cache/rbdem; one JSON file per key,
// written atomically. A cache that cannot be read or written is not an error: the gate just runs.
#pragma once

#include <filesystem>
#include <string>

#include "compare/gate/elastic_gate.hpp"
#include "dem/scene.hpp"

namespace rbdem::compare {

// The "key=value" lines the cache key hashes (for inspection) and the key itself (16 hex digits).
std::string elastic_gate_key_text(const Scene& scene);
std::string elastic_gate_key(const Scene& scene);

// The cache folder from the environment; empty when none can be named.
std::filesystem::path elastic_gate_cache_dir();

struct GateCheck {
  enum class Status { passed, failed, not_applicable };
  Status status = Status::not_applicable;
  bool from_cache = false;
  std::string key;
  std::filesystem::path cache_file;  // where the verdict is (or would have been) stored
  std::string table;                 // elastic_table() of the run
  std::string summary;               // one line: the verdict with its numbers
  std::string note;                  // why not applicable, or why the cache was not written
};

// The verdict for a scene: from the cache when the key is there, else by run_elastic_gate() (then cached).
GateCheck check_elastic_gate(const Scene& scene, const ElasticGateOptions& options = {});

// Stores a finished report under the scene's key (rbdem elastic does this, so a later ucs needs no rerun).
// Returns the file, or an empty path when the cache cannot be written (not an error).
std::filesystem::path store_elastic_gate(const Scene& scene, const ElasticReport& report);

// The scene the elastic gate checks for a test: the gate meshes rectangles at every dip, so a disc's materials are
// checked on the rectangular specimen of the scene's other keys, without confinement (which does not change the
// elastic moduli of the linear model), and on the scene's Delaunay mesh (mesh.structured = false: a structured grid
// holds horizontal joints only).
Scene gate_scene(const Scene& scene);

// For the command line: checks the gate and prints its message (which comparison decided and why) when it passes,
// or the table, the reason and the --skip-elastic-gate hint when it fails. Returns false when the run must be
// refused.
bool require_elastic_gate(const Scene& scene, bool quiet = false);

}  // namespace rbdem::compare
