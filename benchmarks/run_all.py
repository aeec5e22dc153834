"""Run every benchmark script in this folder once and print their tables.

Each ``bench_*.py`` is runnable on its own (``python benchmarks/bench_astar.py``) and also
structured for asv (classes with ``setup``, ``time_*``, ``track_*``). This runner executes the
scripts one after another, so that all ratios in a report come from one run on one machine.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent


def main(names: list[str]) -> int:
    """Run the named benchmarks (``astar``, ``pronto``, …), or all of them."""
    scripts = sorted(HERE.glob("bench_*.py"))
    if names:
        scripts = [s for s in scripts if s.stem.removeprefix("bench_") in names]
    status = 0
    for script in scripts:
        print(f"\n=== {script.name} ===", flush=True)
        status |= subprocess.run([sys.executable, str(script)], check=False).returncode
    return status


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
