// The simulation's figures, side by side in one run on the same model (Laika at the high
// tension point, foot A's motion) and the same time step:
//   - microseconds per step (CPU) of liftoff's engine and of MuJoCo 2.2.2 (the exported
//     MJCF stepped by the cross-check's runner: mj_step1, liftoff's tension-only cable
//     forces into qfrc_applied, mj_step2), replaying the simulated second from t = 8 s
//     (settled, bent, the ramp under way, four feet in contact), both at 1 ms (the step
//     MuJoCo needs: it applies the cable damping explicitly), and liftoff at its default
//     5 ms (the iteration time is then the cost of one simulated second);
//   - wall time of the full 20-run sweep (RunSweep, all cores) and, for comparison, of the
//     same 20 experiments in MuJoCo at 1 ms on as many threads;
//   - the engine's linear solve alone (src/sim/band_cholesky.h) against Eigen's dense LLT
//     on the mid-run step's system at 5 ms: microseconds per factor and solve.
// Targets (issue 6): the sweep under 10 s wall; liftoff faster per step than MuJoCo.
//
// Run: build/bench/sim_bench   (time per iteration = per step, or per sweep)
#include <algorithm>
#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <thread>
#include <vector>

#include <Eigen/Cholesky>
#include <benchmark/benchmark.h>

#include "band_cholesky.h"
#include "liftoff/sim/engine.h"
#include "liftoff/sim/experiment.h"
#include "liftoff/sim/model.h"
#include "liftoff/sim/sweep.h"

#ifndef LIFTOFF_HAVE_MUJOCO
#define LIFTOFF_HAVE_MUJOCO 0
#endif
#if LIFTOFF_HAVE_MUJOCO
#include <mujoco/mujoco.h>

#include "sim/support/mujoco_runner.h"
#endif

namespace {

using namespace liftoff;
using namespace liftoff::sim;

// Mid-run instant the per-step figures start from, s.
constexpr double kMidRunS = 8.0;
// MuJoCo's step in every MuJoCo figure, s.
constexpr double kMujocoStepS = 1e-3;

ModelDescription Laika() {
  auto description = LoadModelDescription(DefaultModelPath());
  if (!description.ok()) {
    std::fprintf(stderr, "%s\n", description.status().ToString().c_str());
    std::exit(1);
  }
  return *description;
}

ExperimentOptions BenchOptions(double time_step_s) {
  ExperimentOptions options;
  options.foot = Foot::kA;
  options.tension_point_index = 4;
  options.engine.time_step_s = time_step_s;
  return options;
}

Model BenchModel(const ExperimentOptions& options) {
  auto model = BuildExperimentModel(Laika(), options);
  if (!model.ok()) {
    std::fprintf(stderr, "%s\n", model.status().ToString().c_str());
    std::exit(1);
  }
  return *model;
}

// Per-step figures: each iteration replays the same simulated second from the mid-run
// state (so both engines time the same stretch: standing, bent, ramp under way, four feet
// on the ground); "per_step" is CPU time per step, the iteration time is per simulated
// second.
constexpr double kWindowS = 1.0;

void CountSteps(benchmark::State& state, double time_step_s, int64_t window_steps) {
  state.counters["per_step"] =
      benchmark::Counter(static_cast<double>(state.iterations() * window_steps),
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  state.counters["dt_ms"] = time_step_s * 1e3;
}

// Steps `sim` through steps first_step .. last_step with the procedure's commands.
void Advance(const Model& model, const ExperimentOptions& options, const Procedure& procedure,
             int64_t first_step, int64_t last_step, State& sim) {
  Controls controls;
  controls.rest_length_m.resize(model.cables.size());
  controls.hinge_angle_rad.resize(1);
  for (int64_t step = first_step; step <= last_step; ++step) {
    const double t_s = procedure.TimeAt(step);
    procedure.RestLengthsAt(t_s, controls.rest_length_m);
    controls.hinge_angle_rad[0] = procedure.HingeAngleAt(t_s);
    Step(model, options.engine, controls, sim);
  }
}

// liftoff's engine: Step with the procedure's commands of the moment.
void BM_LiftoffStep(benchmark::State& state, double time_step_s) {
  const ExperimentOptions options = BenchOptions(time_step_s);
  const Model model = BenchModel(options);
  const Procedure procedure(model, options);
  State sim = InitialState(model, options.drop_height_m);
  const int64_t mid_run = std::llround(kMidRunS / time_step_s);
  const int64_t window = std::llround(kWindowS / time_step_s);
  Advance(model, options, procedure, 1, mid_run, sim);
  const State saved = sim;
  int contacts = 0;
  for (auto _ : state) {
    sim = saved;
    Advance(model, options, procedure, mid_run + 1, mid_run + window, sim);
    contacts = static_cast<int>(sim.scratch.contacts.size());
    benchmark::DoNotOptimize(sim.bodies.data());
  }
  state.counters["contacts"] = contacts;
  CountSteps(state, time_step_s, window);
}

// The engine's linear solve on its own: the velocity system of the mid-run step at the
// default 5 ms (rebuilt from its factor), its band, and as many right-hand sides as the
// step solves (the free velocity change and one per contact row), seeded.
struct MidRunSystem {
  Eigen::MatrixXd matrix;
  Eigen::Index band = 0;
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> rhs;
};

MidRunSystem SystemAtMidRun() {
  const ExperimentOptions options = BenchOptions(5e-3);
  const Model model = BenchModel(options);
  const Procedure procedure(model, options);
  State sim = InitialState(model, options.drop_height_m);
  Advance(model, options, procedure, 1, std::llround(kMidRunS / 5e-3), sim);
  MidRunSystem system;
  const Eigen::MatrixXd factor = sim.scratch.system.triangularView<Eigen::Lower>();
  system.matrix = factor * factor.transpose();
  system.band = sim.scratch.band;
  int rows = 0;
  for (const ContactPoint& contact : sim.scratch.contacts) rows += contact.rows;
  system.rhs.resize(system.matrix.rows(), 1 + rows);
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> entry(-1.0, 1.0);
  for (Eigen::Index i = 0; i < system.rhs.size(); ++i) system.rhs.data()[i] = entry(rng);
  return system;
}

void SolveCounters(benchmark::State& state, const MidRunSystem& system) {
  state.counters["n"] = static_cast<double>(system.matrix.rows());
  state.counters["band"] = static_cast<double>(system.band);
  state.counters["rhs"] = static_cast<double>(system.rhs.cols());
}

// src/sim/band_cholesky.h, as Step uses it: factor in place, solve every column in one pass.
void BM_BandCholeskySolve(benchmark::State& state) {
  const MidRunSystem system = SystemAtMidRun();
  Eigen::MatrixXd work;
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> x;
  for (auto _ : state) {
    work = system.matrix;
    x = system.rhs;
    if (!sim::internal::BandCholesky(work, system.band)) state.SkipWithError("not SPD");
    sim::internal::BandSolveColumns(work, system.band, x.data(), x.cols(), x.cols());
    benchmark::DoNotOptimize(x.data());
  }
  SolveCounters(state, system);
}
BENCHMARK(BM_BandCholeskySolve)->Name("Solve/band_cholesky")->Unit(benchmark::kMicrosecond);

// The same job with Eigen's dense LLT (the library alternative).
void BM_EigenLltSolve(benchmark::State& state) {
  const MidRunSystem system = SystemAtMidRun();
  Eigen::LLT<Eigen::MatrixXd> llt(system.matrix.rows());
  Eigen::MatrixXd x;
  const Eigen::MatrixXd rhs = system.rhs;
  for (auto _ : state) {
    llt.compute(system.matrix);
    x = llt.solve(rhs);
    benchmark::DoNotOptimize(x.data());
  }
  SolveCounters(state, system);
}
BENCHMARK(BM_EigenLltSolve)->Name("Solve/eigen_llt")->Unit(benchmark::kMicrosecond);

#if LIFTOFF_HAVE_MUJOCO
// MuJoCo on the exported model: the runner's Step (cable forces, mj_step1, mj_step2).
void BM_MujocoStep(benchmark::State& state) {
  const ExperimentOptions options = BenchOptions(kMujocoStepS);
  const Model model = BenchModel(options);
  const Procedure procedure(model, options);
  MjcfOptions mjcf;
  mjcf.time_step_s = kMujocoStepS;
  mjcf.lift_m = options.drop_height_m;
  auto created = mujoco::MujocoSimulation::Create(model, mjcf);
  if (!created.ok()) {
    state.SkipWithError(created.status().ToString().c_str());
    return;
  }
  mujoco::MujocoSimulation& simulation = **created;
  std::vector<double> rest(model.cables.size());
  bool failed = false;
  auto advance = [&](int64_t step) {
    const double t_s = procedure.TimeAt(step);
    procedure.RestLengthsAt(t_s, rest);
    failed = failed || !simulation.Step(rest, procedure.HingeAngleAt(t_s)).ok();
  };
  const int64_t mid_run = std::llround(kMidRunS / kMujocoStepS);
  const int64_t window = std::llround(kWindowS / kMujocoStepS);
  for (int64_t step = 1; step <= mid_run; ++step) advance(step);
  const mjModel* m = simulation.mujoco_model();
  mjData* saved = mj_makeData(m);
  mj_copyData(saved, m, simulation.mujoco_data());
  int contacts = 0;
  for (auto _ : state) {
    mj_copyData(simulation.mujoco_data(), m, saved);
    for (int64_t step = mid_run + 1; step <= mid_run + window; ++step) advance(step);
    contacts = simulation.contact_count();
  }
  mj_deleteData(saved);
  if (failed) state.SkipWithError("MuJoCo diverged");
  state.counters["contacts"] = contacts;
  CountSteps(state, kMujocoStepS, window);
}
BENCHMARK(BM_MujocoStep)->Name("MujocoStep/dt_1ms")->Unit(benchmark::kMillisecond);
#endif

// The 20-run sweep as `liftoff sim sweep` runs it: all cores, each run stopped once its
// foot's outcome is settled.
void BM_Sweep(benchmark::State& state) {
  const ModelDescription description = Laika();
  SweepOptions options;
  int stood = 0;
  int threads = 0;
  for (auto _ : state) {
    auto sweep = RunSweep(description, options, {});
    if (!sweep.ok()) {
      state.SkipWithError(sweep.status().ToString().c_str());
      return;
    }
    stood = 0;
    for (const SweepRun& run : sweep->runs) stood += run.Stood() ? 1 : 0;
    threads = sweep->threads;
  }
  state.counters["runs"] = 20;
  state.counters["stood"] = stood;
  state.counters["threads"] = threads;
  state.counters["dt_ms"] = options.base.engine.time_step_s * 1e3;
}
BENCHMARK(BM_Sweep)
    ->Name("Sweep20/liftoff")
    ->Unit(benchmark::kSecond)
    ->Iterations(1)
    ->UseRealTime();

#if LIFTOFF_HAVE_MUJOCO
// The same 20 experiments in MuJoCo at 1 ms, on as many threads as the sweep, each
// stopped 0.02 rad after its first liftoff (or at the end of the ramp).
void BM_MujocoSweep(benchmark::State& state) {
  const ModelDescription description = Laika();
  const int threads = std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  std::atomic<bool> failed{false};
  for (auto _ : state) {
    std::atomic<int> next{0};
    auto work = [&] {
      for (int i = next++; i < 20; i = next++) {
        ExperimentOptions options;
        options.foot = kAllFeet[static_cast<size_t>(i / 5)];
        options.tension_point_index = i % 5;
        options.stop_after_liftoff_rad = 0.02;
        mujoco::MujocoRunOptions run;
        run.substeps = static_cast<int>(std::lround(options.engine.time_step_s / kMujocoStepS));
        if (!mujoco::RunExperimentInMujoco(description, options, run).ok()) failed = true;
      }
    };
    std::vector<std::thread> pool;
    for (int t = 1; t < threads; ++t) pool.emplace_back(work);
    work();
    for (std::thread& thread : pool) thread.join();
  }
  if (failed) state.SkipWithError("a MuJoCo run failed");
  state.counters["runs"] = 20;
  state.counters["threads"] = threads;
  state.counters["dt_ms"] = kMujocoStepS * 1e3;
}
BENCHMARK(BM_MujocoSweep)
    ->Name("Sweep20/mujoco")
    ->Unit(benchmark::kSecond)
    ->Iterations(1)
    ->UseRealTime();
#endif

}  // namespace

BENCHMARK_CAPTURE(BM_LiftoffStep, dt_1ms, 1e-3)
    ->Name("LiftoffStep/dt_1ms")
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_LiftoffStep, dt_5ms, 5e-3)
    ->Name("LiftoffStep/dt_5ms_default")
    ->Unit(benchmark::kMillisecond);

int main(int argc, char** argv) {
  std::printf(
      "liftoff sim bench: Laika (high tension, foot A's motion), per-step figures from "
      "t = %.0f s; MuJoCo %s\n",
      kMidRunS, LIFTOFF_HAVE_MUJOCO ? "2.2.2 via the exported MJCF" : "not built (not found)");
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
