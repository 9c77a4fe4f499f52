"""What calling primseg from Python costs over the C++ run.

Usage: PYTHONPATH=BUILD/python python3 bench/python_overhead.py BUILD/primseg MESH [RUNS] [THREADS]

Alternates, RUNS times each, the CLI's own timing of a piece of work (its `--json` "timing") and
the same work called from Python, and prints medians:
- segment: the CLI's hierarchy_seconds (HierarchyBuilder on the shared mesh, what
  build_hierarchy does) against primseg.segment(mesh) on a mesh read once, and
  primseg.segment(V, F) from numpy arrays (float32, Fortran-ordered int64: conversion and
  checks included);
- skeleton --clusters 20: hierarchy_seconds + skeleton_seconds against primseg.skeleton(mesh, k=20);
- distance to a noisy copy (200000 samples): seconds against primseg.distance(a, b);
- denoise --clusters 30: denoise_seconds, which also reads the input and writes the output,
  against read_mesh + primseg.denoise (no output file: Python gets the array).
Then the work Python adds, which a loaded machine's noise cannot hide: building the C++ mesh
from numpy arrays, and the cost of a call on a one-triangle mesh (medians of 21 and 201).
"""

import json
import os
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

import primseg


def cli_timing(cli, arguments, summary, keys):
    subprocess.run([cli, *arguments], check=True, stdout=subprocess.DEVNULL)
    with open(summary) as f:
        timing = json.load(f)["timing"]
    return sum(timing[key] for key in keys)


def timed(call):
    start = time.perf_counter()
    call()
    return time.perf_counter() - start


def main():
    cli, mesh_path = sys.argv[1], sys.argv[2]
    runs = int(sys.argv[3]) if len(sys.argv) > 3 else 7
    threads = str(int(sys.argv[4]) if len(sys.argv) > 4 else 0)
    mesh = primseg.read_mesh(mesh_path)
    V = mesh.V.astype(np.float32)
    F = np.asfortranarray(mesh.F.astype(np.int64))
    with tempfile.TemporaryDirectory() as folder:
        summary = os.path.join(folder, "s.json")
        noisy_path = os.path.join(folder, "noisy.off")
        noisy_V = mesh.V + np.random.default_rng(1).normal(
            scale=1e-3 * mesh.bounding_box_diagonal, size=mesh.V.shape)
        lines = ["OFF", f"{len(noisy_V)} {len(mesh.F)} 0"]
        lines += [" ".join(map(repr, v)) for v in noisy_V.tolist()]
        lines += ["3 " + " ".join(map(str, f)) for f in mesh.F.tolist()]
        with open(noisy_path, "w") as f:
            f.write("\n".join(lines) + "\n")
        noisy = primseg.read_mesh(noisy_path)
        n = int(threads)
        # (name, CLI arguments, timing keys, the same work from Python)
        work = [
            ("segment", ["segment", mesh_path, "--quiet", "--clusters", "1", "--threads", threads,
                         "--json", summary], ["hierarchy_seconds"],
             {"segment(mesh)": lambda: primseg.segment(mesh, threads=n),
              "segment(V32, F64 Fortran)": lambda: primseg.segment(V, F, threads=n)}),
            ("skeleton", ["skeleton", mesh_path, "--quiet", "--clusters", "20", "--threads", threads,
                          "-o", summary], ["hierarchy_seconds", "skeleton_seconds"],
             {"skeleton(mesh, k=20)": lambda: primseg.skeleton(mesh, k=20, threads=n)}),
            ("distance", ["distance", mesh_path, noisy_path, "--quiet", "--threads", threads,
                          "--json", summary], ["seconds"],
             {"distance(a, b)": lambda: primseg.distance(mesh, noisy, threads=n)}),
            ("denoise", ["denoise", noisy_path, "--quiet", "--clusters", "30", "--threads", threads,
                         "-o", os.path.join(folder, "out.off"), "--json", summary],
             ["denoise_seconds"],
             {"read_mesh + denoise(k=30)":
              lambda: primseg.denoise(primseg.read_mesh(noisy_path), k=30, threads=n)}),
        ]
        times = {name: {"C++ (CLI timing)": []} | {p: [] for p in calls} for name, _, _, calls in work}
        for _ in range(runs):
            for name, arguments, keys, calls in work:
                times[name]["C++ (CLI timing)"].append(cli_timing(cli, arguments, summary, keys))
                for label, call in calls.items():
                    times[name][label].append(timed(call))
    print(f"{os.path.basename(mesh_path)}: {mesh.face_count} faces, {runs} runs, threads={threads}")
    for name, table in times.items():
        reference = statistics.median(table["C++ (CLI timing)"])
        print(name)
        for label, values in table.items():
            median = statistics.median(values)
            print(f"  {label:28s} median {median * 1e3:8.1f} ms  ({(median / reference - 1) * 100:+.1f}%)"
                  f"  min {min(values) * 1e3:8.1f} ms")
    python_side(mesh, V, F)


def python_side(mesh, V, F):
    def median(call, repeats):
        return statistics.median(timed(call) for _ in range(repeats))

    tiny = primseg.Mesh(np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]]), np.array([[0, 1, 2]]))
    print("Python-side work")
    print(f"  Mesh(V32, F64 Fortran)        {median(lambda: primseg.Mesh(V, F), 21) * 1e3:8.2f} ms")
    print(f"  Mesh(mesh.V, mesh.F)          {median(lambda: primseg.Mesh(mesh.V, mesh.F), 21) * 1e3:8.2f} ms")
    print(f"  segment(one triangle)         {median(lambda: primseg.segment(tiny), 201) * 1e6:8.1f} us")


if __name__ == "__main__":
    main()
