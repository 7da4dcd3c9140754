"""The cost of a protocol written in Python (docs/python.md, "The cost of Python"): wall time per explicit step of
a test whose Python hooks step() and done() run every 1, 10 or 100 steps, against the same test with one call in
all (none), on the default scene (about 13 000 blocks) with its platens closing at the paper's speed. Each row is
the median of REPEATS runs of STEPS steps, alternating. With one engine thread (the default here) the process's
CPU time per step measures the cost even on a busy machine; THREADS=0 uses the scene's threads (wall time then
needs an idle machine):

    PYTHONPATH=build/python /usr/bin/python3 benchmarks/python_callbacks.py [STEPS] [REPEATS]
    MESH=0.004 PYTHONPATH=build/python /usr/bin/python3 benchmarks/python_callbacks.py 20000 5
"""
import os
import statistics
import sys
import time

import rbdem


class Load(rbdem.Protocol):
    """The platens close at 0.01 m/s; step() reads the platen stress, as a servo would."""
    name = "load"

    def __init__(self, every, steps):
        self.every, self.max_steps, self.steps = every, steps, steps
        self.reads = 0

    def prepare(self, sim):
        self.platens = sim.add_platens(velocity=0.01)

    def start(self, sim):
        self.clock = (time.perf_counter(), time.process_time(), sim.steps)

    def step(self, sim):
        self.reads += 1
        _ = self.platens.stress

    def done(self, sim):
        if sim.steps < self.steps:
            return False
        w0, c0, s0 = self.clock
        self.per_step = ((time.perf_counter() - w0) / (sim.steps - s0), (time.process_time() - c0) / (sim.steps - s0))
        return True


THREADS = int(os.environ.get("THREADS", "1"))
MESH = os.environ.get("MESH")  # mesh.size in m; a coarse mesh (few blocks, short steps) shows the cost per call


def seconds_per_step(every, steps):
    """(wall, CPU) seconds per explicit step of one run, from its first explicit step to its last (the set-up of
    the run, the same for every case, left out)."""
    sets = {"numerics.elastic_start": False}
    if THREADS:
        sets["numerics.threads"] = THREADS
    if MESH:
        sets["mesh.size"] = float(MESH)
    sim = rbdem.Simulation(overrides=sets)
    load = Load(every, steps)
    sim.run(load)
    return load.per_step


def main():
    steps = int(sys.argv[1]) if len(sys.argv) > 1 else 3000
    repeats = int(sys.argv[2]) if len(sys.argv) > 2 else 3
    cases = [("none", steps), ("every 100", 100), ("every 10", 10), ("every step", 1)]
    times = {name: [] for name, _ in cases}
    for _ in range(repeats):
        for name, every in cases:
            times[name].append(seconds_per_step(every, steps))
    scene = f"mesh.size = {MESH} m" if MESH else "the default scene"
    print(f"{steps} steps, {scene}, {THREADS or 'the default'} engine thread(s), medians of {repeats}")
    print("| Python hooks | wall us per step | CPU us per step | CPU over none | CPU us per call |")
    print("|---|---:|---:|---:|---:|")
    base = statistics.median(c for _, c in times["none"])
    for name, every in cases:
        wall = statistics.median(w for w, _ in times[name])
        cpu = statistics.median(c for _, c in times[name])
        calls = steps / every if every < steps else 1
        per_call = (cpu - base) * steps / calls * 1e6 if name != "none" else 0.0
        print(f"| {name} | {wall * 1e6:.1f} | {cpu * 1e6:.1f} | {100 * (cpu / base - 1):+.1f} % | {per_call:.2f} |")


if __name__ == "__main__":
    main()
