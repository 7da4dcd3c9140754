// ARKODE reference and implicit integrators on the engine's force evaluation; the synchronised central difference.
// See reference_integrator.hpp.
#include "compare/reference_integrator.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <numeric>
#include <stdexcept>
#include <string>
#include <time.h>
#include <type_traits>

#include <arkode/arkode_arkstep.h>
#include <arkode/arkode_erkstep.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sunlinsol/sunlinsol_band.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_band.h>
#include <sunmatrix/sunmatrix_dense.h>

#include "dem/specimen_mesh.hpp"
#include "dem/static_solve.hpp"

namespace rbdem {

namespace {

using Clock = std::chrono::steady_clock;

// The platens attached to the engine, if any.
PlatensImpl<2>* platens_of(const Engine<2>& engine) {
  for (BoundaryHooks<2>* h : engine.hooks())
    if (auto* p = dynamic_cast<PlatensImpl<2>*>(h)) return p;
  return nullptr;
}

double thread_cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

void check_flag(int flag, const char* call) {
  if (flag < 0) throw std::runtime_error(std::string("SUNDIALS: ") + call + " failed with flag " + std::to_string(flag));
}

// Owners of the SUNDIALS objects of one integration (released in reverse order of creation).
struct Sundials {
  SUNContext ctx = nullptr;
  N_Vector y = nullptr, atol = nullptr;
  SUNMatrix A = nullptr;
  SUNLinearSolver LS = nullptr;
  void* mem = nullptr;
  bool erk = true;

  explicit Sundials(sunindextype n) {
    check_flag(SUNContext_Create(nullptr, &ctx), "SUNContext_Create");
    y = N_VNew_Serial(n, ctx);
    atol = N_VNew_Serial(n, ctx);
    if (!y || !atol) throw std::runtime_error("SUNDIALS: N_VNew_Serial failed");
  }
  Sundials(const Sundials&) = delete;
  Sundials& operator=(const Sundials&) = delete;
  ~Sundials() {
    if (mem) {
      if (erk) ERKStepFree(&mem);
      else ARKStepFree(&mem);
    }
    if (LS) SUNLinSolFree(LS);
    if (A) SUNMatDestroy(A);
    if (atol) N_VDestroy(atol);
    if (y) N_VDestroy(y);
    if (ctx) SUNContext_Free(&ctx);
  }
};

// The right-hand side. Slot s of the ODE vector holds block order[s] (a renumbering for a banded Jacobian).
struct BlockOde {
  Engine<2>& engine;
  std::vector<int> order;
  std::vector<double> fx, fy, m;

  PlatensImpl<2>* platens;  // the engine's platens, if any
  double top0;              // m, the top platen's position at t = 0

  BlockOde(Engine<2>& e, std::vector<int> o)
      : engine(e), order(std::move(o)), platens(platens_of(e)), top0(platens ? platens->top_y() : 0.0) {}

  // Loads the state vector (ODE order) into the engine and puts the top platen where it is at time t.
  void load(double t, const double* y) {
    engine.edit([&](ModelState<2>& st) {
      for (std::size_t s = 0; s < order.size(); ++s) {
        const std::size_t b = std::size_t(order[s]);
        const double* q = y + 6 * s;
        st.x[b] = q[0], st.y[b] = q[1], st.theta[b] = q[2], st.vx[b] = q[3], st.vy[b] = q[4], st.omega[b] = q[5];
      }
    });
    if (platens) platens->set_top_y(top0 - platens->velocity() * t);
  }

  void eval(double t, const double* y, double* ydot) {
    load(t, y);
    engine.evaluate_forces(fx, fy, m);
    const Model<2>& M = engine.model();
    for (std::size_t s = 0; s < order.size(); ++s) {
      const std::size_t b = std::size_t(order[s]);
      const double* q = y + 6 * s;
      double* d = ydot + 6 * s;
      if (M.fixed[b]) {
        std::fill(d, d + 6, 0.0);
        continue;
      }
      d[0] = q[3], d[1] = q[4], d[2] = q[5];
      d[3] = fx[b] / M.mass[b], d[4] = fy[b] / M.mass[b], d[5] = m[b] / M.inertia[b];
    }
  }

  static int rhs(sunrealtype t, N_Vector y, N_Vector ydot, void* user) {
    static_cast<BlockOde*>(user)->eval(double(t), N_VGetArrayPointer(y), N_VGetArrayPointer(ydot));
    return 0;
  }

  void to_ode(const BlockStateVector& in, double* out) const {
    for (std::size_t s = 0; s < order.size(); ++s)
      std::copy_n(in.data() + 6 * std::size_t(order[s]), 6, out + 6 * s);
  }
  BlockStateVector from_ode(const double* in) const {
    BlockStateVector out(6 * order.size());
    for (std::size_t s = 0; s < order.size(); ++s) std::copy_n(in + 6 * s, 6, out.data() + 6 * std::size_t(order[s]));
    return out;
  }
};

std::vector<int> identity_order(std::size_t n) {
  std::vector<int> o(n);
  std::iota(o.begin(), o.end(), 0);
  return o;
}

void set_tolerances(Sundials& s, const BlockStateVector& y0, const Tolerances& tol, const BlockOde& ode) {
  double* a = N_VGetArrayPointer(s.atol);
  for (std::size_t k = 0; k < y0.size(); ++k) a[k] = tol.atol[k % 6];
  ode.to_ode(y0, N_VGetArrayPointer(s.y));
}

}  // namespace

// The reference integrators' state vector holds the kinematic fields of ModelState's field table (dem/state.hpp), in
// table order, block by block.
BlockStateVector get_state(const Engine<2>& engine) {
  const std::size_t n = engine.model().num_blocks();
  BlockStateVector y(6 * n);
  int k = 0;
  engine.state().fields([&](const char*, const auto& field, Extent, bool kinematic) {
    if constexpr (std::is_same_v<std::decay_t<decltype(field)>, std::vector<double>>) {
      if (!kinematic) return;
      for (std::size_t b = 0; b < n; ++b) y[6 * b + std::size_t(k)] = field[b];
      ++k;
    }
  });
  return y;
}

void set_state(Engine<2>& engine, const BlockStateVector& y) {
  const std::size_t n = engine.model().num_blocks();
  if (y.size() != 6 * n)
    throw std::invalid_argument("set_state: the state vector has " + std::to_string(y.size()) + " entries, the engine " +
                                std::to_string(n) + " blocks (6 entries each)");
  engine.edit([&](ModelState<2>& s) {
    int k = 0;
    s.fields([&](const char*, auto& field, Extent, bool kinematic) {
      if constexpr (std::is_same_v<std::decay_t<decltype(field)>, std::vector<double>>) {
        if (!kinematic) return;
        for (std::size_t b = 0; b < n; ++b) field[b] = y[6 * b + std::size_t(k)];
        ++k;
      }
    });
  });
}

void check_reference_scope(const Engine<2>& engine, double damping) {
  if (damping != 0.0)
    throw std::invalid_argument("reference integrator: the equations of motion are undamped; set numerics.damping = 0");
  if (engine.state().breakage)
    throw std::invalid_argument("reference integrator: a bond breaking is an event the ODE does not model; call "
                                "engine.set_breakage(false)");
  if (const PlatensImpl<2>* platens = platens_of(engine); platens && platens->friction() != 0.0)
    throw std::invalid_argument("reference integrator: frictional platens carry a shear history; set "
                                "loading.platen_friction = 0");
  const Model<2>& M = engine.model();
  for (std::size_t k = 0; k < M.law.size(); ++k) {
    if (std::find(M.material.begin(), M.material.end(), std::uint8_t(k)) == M.material.end()) continue;  // unused
    const BondKindLaw& law = M.law[k];
    if (!(law.mu == 0.0 && law.slip_bonded))
      throw std::invalid_argument("reference integrator: the linear part's and the contacts' incremental shear "
                                  "carries history; set contact_friction = 0 and slip_when_bonded = true for "
                                  "every material in use (rock, joint, joint2, rock2)");
  }
}

Tolerances Tolerances::scaled(double rtol, double u, double v, double l) {
  Tolerances t;
  t.rtol = rtol;
  t.atol = {rtol * u, rtol * u, rtol * u / l, rtol * v, rtol * v, rtol * v / l};
  return t;
}

IntegrationResult integrate_explicit(Engine<2>& engine, const BlockStateVector& y0, double t_end, const Tolerances& tol,
                                     ExplicitTable table) {
  const auto start = Clock::now();
  const double cpu_start = thread_cpu_seconds();
  BlockOde ode(engine, identity_order(engine.model().num_blocks()));
  Sundials s(sunindextype(y0.size()));
  set_tolerances(s, y0, tol, ode);
  s.erk = true;
  s.mem = ERKStepCreate(&BlockOde::rhs, 0.0, s.y, s.ctx);
  if (!s.mem) throw std::runtime_error("SUNDIALS: ERKStepCreate failed");
  check_flag(ERKStepSetUserData(s.mem, &ode), "ERKStepSetUserData");
  check_flag(ERKStepSVtolerances(s.mem, tol.rtol, s.atol), "ERKStepSVtolerances");
  const ARKODE_ERKTableID id = table == ExplicitTable::fehlberg_13_7_8 ? ARKODE_FEHLBERG_13_7_8
                               : table == ExplicitTable::verner_8_5_6  ? ARKODE_VERNER_8_5_6
                                                                       : ARKODE_DORMAND_PRINCE_7_4_5;
  check_flag(ERKStepSetTableNum(s.mem, id), "ERKStepSetTableNum");
  check_flag(ERKStepSetMaxNumSteps(s.mem, 100000000), "ERKStepSetMaxNumSteps");
  check_flag(ERKStepSetStopTime(s.mem, t_end), "ERKStepSetStopTime");  // land on t_end, no dense output
  sunrealtype t = 0.0;
  check_flag(ERKStepEvolve(s.mem, t_end, s.y, &t, ARK_NORMAL), "ERKStepEvolve");
  if (ode.platens) ode.platens->set_top_y(ode.top0);  // the next integration starts from the same platen position
  IntegrationResult r;
  r.state = ode.from_ode(N_VGetArrayPointer(s.y));
  long v = 0;
  ERKStepGetNumSteps(s.mem, &v), r.stats.steps = v;
  ERKStepGetNumStepAttempts(s.mem, &v), r.stats.attempts = v;
  ERKStepGetNumRhsEvals(s.mem, &v), r.stats.rhs_evals = v;
  r.stats.wall_seconds = std::chrono::duration<double>(Clock::now() - start).count();
  r.stats.cpu_seconds = thread_cpu_seconds() - cpu_start;
  return r;
}

IntegrationResult integrate_implicit(Engine<2>& engine, const BlockStateVector& y0, double t_end, const Tolerances& tol,
                                     const ImplicitOptions& options) {
  const auto start = Clock::now();
  const double cpu_start = thread_cpu_seconds();
  const std::size_t nb = engine.model().num_blocks();
  std::vector<int> order = identity_order(nb);
  sunindextype half_band = 0;
  if (options.solver == LinearSolver::band) {
    // Number the blocks along the longer side: bonded blocks then sit close in the numbering.
    const bool along_x = engine.model().width >= engine.model().height;
    std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
      const ModelState<2>& st = engine.state();
      return along_x ? st.x[std::size_t(a)] < st.x[std::size_t(b)] : st.y[std::size_t(a)] < st.y[std::size_t(b)];
    });
    std::vector<int> slot(nb);
    for (std::size_t s = 0; s < nb; ++s) slot[std::size_t(order[s])] = int(s);
    int width = 0;
    const Model<2>& M = engine.model();
    for (std::size_t b = 0; b < M.num_bonds(); ++b)
      width = std::max(width, std::abs(slot[std::size_t(M.bi[b])] - slot[std::size_t(M.bj[b])]));
    half_band = 6 * width + 5;  // every entry of block s couples to every entry of blocks s +- width
  }
  BlockOde ode(engine, std::move(order));
  const auto n = sunindextype(y0.size());
  Sundials s(n);
  set_tolerances(s, y0, tol, ode);
  s.erk = false;
  s.mem = ARKStepCreate(nullptr, &BlockOde::rhs, 0.0, s.y, s.ctx);
  if (!s.mem) throw std::runtime_error("SUNDIALS: ARKStepCreate failed");
  check_flag(ARKStepSetUserData(s.mem, &ode), "ARKStepSetUserData");
  check_flag(ARKStepSVtolerances(s.mem, tol.rtol, s.atol), "ARKStepSVtolerances");
  const ARKODE_DIRKTableID id = options.table == ImplicitTable::sdirk_5_3_4    ? ARKODE_SDIRK_5_3_4
                                : options.table == ImplicitTable::kvaerno_7_4_5 ? ARKODE_KVAERNO_7_4_5
                                                                                : ARKODE_TRBDF2_3_3_2;
  check_flag(ARKStepSetTableNum(s.mem, id, ARKODE_ERK_NONE), "ARKStepSetTableNum");
  if (options.solver == LinearSolver::band) {
    s.A = SUNBandMatrix(n, half_band, half_band, s.ctx);
    s.LS = SUNLinSol_Band(s.y, s.A, s.ctx);
  } else {
    s.A = SUNDenseMatrix(n, n, s.ctx);
    s.LS = SUNLinSol_Dense(s.y, s.A, s.ctx);
  }
  if (!s.A || !s.LS) throw std::runtime_error("SUNDIALS: creating the matrix or the linear solver failed");
  check_flag(ARKStepSetLinearSolver(s.mem, s.LS, s.A), "ARKStepSetLinearSolver");  // no Jacobian: difference quotients
  check_flag(ARKStepSetMaxNumSteps(s.mem, 100000000), "ARKStepSetMaxNumSteps");
  check_flag(ARKStepSetStopTime(s.mem, t_end), "ARKStepSetStopTime");
  sunrealtype t = 0.0;
  check_flag(ARKStepEvolve(s.mem, t_end, s.y, &t, ARK_NORMAL), "ARKStepEvolve");
  if (ode.platens) ode.platens->set_top_y(ode.top0);
  IntegrationResult r;
  r.state = ode.from_ode(N_VGetArrayPointer(s.y));
  long v = 0, fe = 0, fi = 0;
  ARKStepGetNumSteps(s.mem, &v), r.stats.steps = v;
  ARKStepGetNumStepAttempts(s.mem, &v), r.stats.attempts = v;
  ARKStepGetNumRhsEvals(s.mem, &fe, &fi);
  ARKStepGetNumLinRhsEvals(s.mem, &v);
  r.stats.rhs_evals = fe + fi + v;
  ARKStepGetNumNonlinSolvIters(s.mem, &v), r.stats.newton_iters = v;
  ARKStepGetNumJacEvals(s.mem, &v), r.stats.jacobian_evals = v;
  r.stats.wall_seconds = std::chrono::duration<double>(Clock::now() - start).count();
  r.stats.cpu_seconds = thread_cpu_seconds() - cpu_start;
  return r;
}

IntegrationResult central_difference(Engine<2>& engine, const BlockStateVector& y0, double dt, long steps) {
  const auto start = Clock::now();
  const double cpu_start = thread_cpu_seconds();
  std::vector<double> fx, fy, m;
  const Model<2>& M = engine.model();
  auto half_kick = [&](double sign) {
    engine.evaluate_forces(fx, fy, m);
    engine.edit([&](ModelState<2>& s) {
      for (std::size_t b = 0; b < M.num_blocks(); ++b) {
        if (M.fixed[b]) continue;
        s.vx[b] += sign * 0.5 * dt * fx[b] / M.mass[b];
        s.vy[b] += sign * 0.5 * dt * fy[b] / M.mass[b];
        s.omega[b] += sign * 0.5 * dt * m[b] / M.inertia[b];
      }
    });
  };
  PlatensImpl<2>* platens = platens_of(engine);
  const double top0 = platens ? platens->top_y() : 0.0;
  set_state(engine, y0);
  half_kick(-1.0);  // v(-dt/2): the leapfrog's staggered start
  engine.set_dt(dt);
  engine.run(steps);
  half_kick(+1.0);  // v(T) from v(T - dt/2)
  IntegrationResult r;
  r.state = get_state(engine);
  if (platens) platens->set_top_y(top0);  // the next integration starts from the same platen position
  r.stats.steps = r.stats.attempts = steps;
  r.stats.rhs_evals = steps + 2;
  r.stats.wall_seconds = std::chrono::duration<double>(Clock::now() - start).count();
  r.stats.cpu_seconds = thread_cpu_seconds() - cpu_start;
  return r;
}

StateError state_error(const Engine<2>& engine, const BlockStateVector& y, const BlockStateVector& ref,
                       const BlockStateVector& y0) {
  double dq = 0, uq = 0, dv = 0, vv = 0;
  for (std::size_t b = 0; b < engine.model().num_blocks(); ++b) {
    const double r = engine.model().radius[b];
    const double* a = y.data() + 6 * b;
    const double* e = ref.data() + 6 * b;
    const double* o = y0.data() + 6 * b;
    for (int k = 0; k < 6; ++k) {
      const double w = (k == 2 || k == 5) ? r : 1.0;  // rotations as arc lengths of the block's radius
      const double diff = w * (a[k] - e[k]);
      if (k < 3) dq += diff * diff, uq += std::pow(w * (e[k] - o[k]), 2);
      else dv += diff * diff, vv += std::pow(w * e[k], 2);
    }
  }
  return {std::sqrt(dq / uq), std::sqrt(dv / vv)};
}

std::unique_ptr<SimulationImpl<2>> ReferenceProblem::make_simulation() const {
  Scene s = scene;
  s.numerics.threads = 1;
  auto sim = std::make_unique<SimulationImpl<2>>(s, *topology, SimulationOptions{}, [this](EngineOptions& o) {
    o.contacts = specimen.platens || specimen.break_joints;
  });
  Engine<2>& e = sim->engine();
  e.set_breakage(false);
  const auto& bd = topology->boundary;
  for (std::size_t k = 0; k < bd.size(); ++k)
    if (bd.side[k] == Side::bottom) e.fix_block(bd.block[k]);
  if (specimen.break_joints)
    for (std::size_t b = 0; b < topology->bonds.size(); ++b)
      if (topology->bonds.kind[b] == BondKind::joint) e.break_bond(int(b));
  // The top platen starts where the initial field has moved the top of the specimen, so that it touches it.
  if (specimen.platens)
    static_cast<PlatensImpl<2>&>(sim->add_platens({specimen.platen_velocity, 0.0}))
        .set_top_y(topology->ymax - specimen.strain * topology->height());
  check_reference_scope(e, s.numerics.damping);
  return sim;
}

ReferenceProblem make_reference_problem(const ReferenceSpecimen& sp) {
  ReferenceProblem p;
  p.specimen = sp;
  Scene& s = p.scene;
  s.specimen.width = sp.width, s.specimen.height = sp.height;
  s.joint_set.dip_deg = sp.dip_deg, s.joint_set.spacing = sp.spacing;
  s.mesh.size = sp.mesh_size;
  s.numerics.damping = 0.0;
  s.loading.platen_friction = 0.0;
  s.joint.effective_modulus = s.rock.effective_modulus / sp.joint_contrast;
  for (MaterialParams* m : {static_cast<MaterialParams*>(&s.rock), &s.joint}) {
    m->contact_friction = 0.0;
    m->slip_when_bonded = true;
  }
  p.topology = std::make_unique<Topology<2>>(build_topology(make_mesh(s), s.specimen.thickness, s.rock.density));
  p.sim = p.make_simulation();
  p.stability_limit = p.sim->stability_limit(300, 1);

  const Engine<2>& e = p.sim->engine();
  const Topology<2>& topo = *p.topology;
  const Model<2>& M = e.model();
  const double ymin = topo.ymin, H = topo.height();
  // Mean height of each layer's blocks (layer_rigid).
  const int layers = 1 + *std::max_element(topo.blocks.layer.begin(), topo.blocks.layer.end());
  std::vector<double> ysum(std::size_t(layers), 0.0), count(std::size_t(layers), 0.0);
  std::vector<std::uint8_t> clamped(std::size_t(layers), 0);  // layers with a fixed block stay at rest
  for (std::size_t b = 0; b < M.num_blocks(); ++b) {
    const std::size_t l = std::size_t(topo.blocks.layer[b]);
    ysum[l] += topo.blocks.cy[b], count[l] += 1.0;
    if (M.fixed[b]) clamped[l] = 1;
  }
  p.y0 = get_state(e);
  for (std::size_t b = 0; b < M.num_blocks(); ++b) {
    if (M.fixed[b]) continue;
    double* q = p.y0.data() + 6 * b;
    const double y = topo.blocks.cy[b] - ymin;
    if (sp.field == InitialField::smooth) {
      q[1] -= sp.strain * y;
      q[3] = sp.velocity * std::sin(0.5 * std::numbers::pi * y / H);
    } else {
      const std::size_t l = std::size_t(topo.blocks.layer[b]);
      if (!clamped[l]) q[3] = sp.velocity * std::sin(0.5 * std::numbers::pi * (ysum[l] / count[l] - ymin) / H);
    }
  }
  return p;
}

}  // namespace rbdem
