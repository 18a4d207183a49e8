"""Compile time: the first solve in a fresh environment, and a cached start.

    python benchmarks/bench_compile.py [--scenes j125 s67 s67_3d]

For each scene, two fresh interpreters in turn, sharing one NUMBA_CACHE_DIR
that starts empty: the first compiles every kernel the scene's solve uses
(*first*), the second loads them from the cache (*cached*). Each reports the
import and the first solve apart. Scenes are compiled into caches of their
own, so a 3D scene's figure does not include the planar kernels. Machine and
versions are printed with the table (markdown on stdout).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

from bench_jlay import STARTUP_SCRIPT, machine_info

import pipelay_fast as pf

EXAMPLES = Path(pf.__file__).parent / "examples"


def startup(case_file: Path, cache_dir: str) -> dict:
    """Import and first-solve seconds of a fresh interpreter using ``cache_dir``."""
    env = {**os.environ, "NUMBA_CACHE_DIR": cache_dir}
    out = subprocess.run([sys.executable, "-c", STARTUP_SCRIPT, str(case_file)], env=env,
                         capture_output=True, text=True, check=True).stdout
    return json.loads(out.strip().splitlines()[-1])


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenes", nargs="+", default=["j125", "s67", "s67_3d"])
    args = parser.parse_args(argv)
    info = machine_info()
    print("## Machine\n")
    for key, value in info.items():
        print(f"- {key}: {value}")
    print("\n| scene | first: import s | first: solve s | cached: import s | cached: solve s |")
    print("| --- | --- | --- | --- | --- |")
    for scene in args.scenes:
        with tempfile.TemporaryDirectory() as cache:
            first = startup(EXAMPLES / f"{scene}.toml", cache)
            cached = startup(EXAMPLES / f"{scene}.toml", cache)
        print(f"| {scene} | {first['import_s']:.2f} | {first['first_solve_s']:.1f} | "
              f"{cached['import_s']:.2f} | {cached['first_solve_s']:.2f} |", flush=True)


if __name__ == "__main__":
    main()
