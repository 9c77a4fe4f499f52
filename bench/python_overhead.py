"""What calling primseg from Python costs over the C++ run.

Usage: PYTHONPATH=BUILD/python python3 bench/python_overhead.py BUILD/primseg MESH [RUNS] [THREADS]

Alternates, RUNS times each: the CLI's own timing of the hierarchy (`--json` timing
hierarchy_seconds: HierarchyBuilder on the shared mesh, what build_hierarchy does), Python's
primseg.segment(mesh) on a mesh read once, and primseg.segment(V, F) from numpy arrays
(float32, Fortran-ordered int64: conversion and checks included). Prints medians.
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


def main():
    cli, mesh_path = sys.argv[1], sys.argv[2]
    runs = int(sys.argv[3]) if len(sys.argv) > 3 else 7
    threads = int(sys.argv[4]) if len(sys.argv) > 4 else 0
    mesh = primseg.read_mesh(mesh_path)
    V = mesh.V.astype(np.float32)
    F = np.asfortranarray(mesh.F.astype(np.int64))
    times = {"C++ (CLI timing)": [], "segment(mesh)": [], "segment(V32, F64 Fortran)": []}
    with tempfile.TemporaryDirectory() as folder:
        summary = os.path.join(folder, "s.json")
        for _ in range(runs):
            subprocess.run([cli, "segment", mesh_path, "--quiet", "--clusters", "1",
                            "--threads", str(threads), "--json", summary], check=True)
            with open(summary) as f:
                times["C++ (CLI timing)"].append(json.load(f)["timing"]["hierarchy_seconds"])
            start = time.perf_counter()
            primseg.segment(mesh, threads=threads)
            times["segment(mesh)"].append(time.perf_counter() - start)
            start = time.perf_counter()
            primseg.segment(V, F, threads=threads)
            times["segment(V32, F64 Fortran)"].append(time.perf_counter() - start)
    reference = statistics.median(times["C++ (CLI timing)"])
    print(f"{os.path.basename(mesh_path)}: {mesh.face_count} faces, {runs} runs, threads={threads}")
    for name, values in times.items():
        median = statistics.median(values)
        print(f"  {name:28s} median {median * 1e3:8.1f} ms  ({(median / reference - 1) * 100:+.1f}%)"
              f"  min {min(values) * 1e3:8.1f} ms")


if __name__ == "__main__":
    main()
