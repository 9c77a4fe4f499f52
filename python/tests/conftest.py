"""Shared fixtures: real meshes from Debian's libcgal-demo, the CLI built beside the module, and
small generated solids with known primitives."""

import os
import pathlib
import subprocess
import tarfile
import threading
import time

import numpy as np
import pytest

CGAL_ARCHIVE = pathlib.Path("/usr/share/doc/libcgal-dev/data.tar.gz")


@pytest.fixture(scope="session")
def cgal_mesh(tmp_path_factory):
    """Path of a mesh from libcgal-demo's archive (fails, not skips, when it is missing)."""
    directory = tmp_path_factory.mktemp("cgal")

    def extract(name):
        target = directory / name
        if not target.exists():
            with tarfile.open(CGAL_ARCHIVE) as archive:
                member = archive.extractfile(f"data/meshes/{name}")
                target.write_bytes(member.read())
        return target

    return extract


@pytest.fixture(scope="session")
def fandisk(cgal_mesh):
    return cgal_mesh("fandisk.off")


@pytest.fixture(scope="session")
def cli():
    """The primseg executable of the same build (CTest passes it in PRIMSEG_CLI)."""
    path = os.environ.get("PRIMSEG_CLI", "")
    if not path:
        pytest.skip("PRIMSEG_CLI not set (build without the CLI)")
    return pathlib.Path(path)


def capped_cylinder(radius=2.0, height=5.0, around=48, rings=8, center=(1.0, -2.0, 0.5)):
    """A closed cylinder along z (tube plus two fan caps): V (n, 3) float64, F (m, 3) int64 and the
    ground-truth region of each face (0 tube, 1 bottom cap, 2 top cap)."""
    angles = 2 * np.pi * np.arange(around) / around
    ring = np.stack([radius * np.cos(angles), radius * np.sin(angles)], axis=1)
    heights = np.linspace(0.0, height, rings + 1)
    tube = np.concatenate([np.column_stack([ring, np.full(around, z)]) for z in heights])
    V = np.vstack([tube, [[0, 0, 0], [0, 0, height]]]) + np.asarray(center)
    bottom, top = len(tube), len(tube) + 1
    faces, regions = [], []
    for r in range(rings):
        for i in range(around):
            a, b = r * around + i, r * around + (i + 1) % around
            faces += [[a, b, b + around], [a, b + around, a + around]]
            regions += [0, 0]
    for i in range(around):
        j = (i + 1) % around
        faces.append([bottom, j, i])
        faces.append([top, rings * around + i, rings * around + j])
        regions += [1, 2]
    return V, np.asarray(faces, dtype=np.int64), np.asarray(regions)


def same_partition(a, b):
    """True when two label arrays group the faces identically (whatever the label values)."""
    a, b = np.asarray(a), np.asarray(b)
    pairs = np.unique(np.stack([a, b]), axis=1)
    return len(pairs[0]) == len(np.unique(a)) == len(np.unique(b))


def run_cli(cli, *args):
    """Runs the primseg executable; returns its standard output."""
    # Under the sanitizer build the interpreter runs with the ASan runtime preloaded; the CLI
    # carries its own and must not get a second one.
    env = {k: v for k, v in os.environ.items() if k != "LD_PRELOAD"}
    return subprocess.run([str(cli), *map(str, args)], check=True, capture_output=True, env=env,
                          text=True).stdout


def write_off(path, V, F):
    """An OFF file whose coordinates read back bit for bit (repr is the shortest round trip)."""
    lines = ["OFF", f"{len(V)} {len(F)} 0"] + [" ".join(map(repr, v)) for v in np.asarray(V).tolist()]
    lines += [" ".join(map(str, [len(f), *f])) for f in np.asarray(F).tolist()]
    pathlib.Path(path).write_text("\n".join(lines) + "\n")


def assert_releases_the_gil(call):
    """Runs call() in a thread while this one ticks: holding the GIL would freeze the ticks for
    the whole call, one gap as long as the call."""
    span = {}

    def work():
        span["start"] = time.perf_counter()
        call()
        span["end"] = time.perf_counter()

    worker = threading.Thread(target=work)
    ticks = []
    worker.start()
    while worker.is_alive():
        ticks.append(time.perf_counter())
        time.sleep(0.001)
    worker.join()
    inside = [t for t in ticks if span["start"] < t < span["end"]]
    duration = span["end"] - span["start"]
    gaps = np.diff([span["start"], *inside, span["end"]])
    assert gaps.max() < duration / 2, (gaps.max(), duration)
