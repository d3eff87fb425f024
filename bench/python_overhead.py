"""What calling mcrewave through Python costs on the paper's case, against the binary
(issue goal: under 5 % more), measured side by side in one run.

    /usr/bin/python3 bench/python_overhead.py [--build build] [--runs 5]
                     [--config configs/paper_bar.yaml]

Runs, alternately (A B A B ...), each as a process of its own from the checkout:
  A  build/identify/identify run CONFIG -q -o TMP --set output.figures=false
  B  python3 -c "import mcrewave; mcrewave.identify(CONFIG, ...).write(TMP, figures=False)"
and prints each one's median wall time, B's median time inside its identify and write
calls (the call alone, the interpreter's start and the import apart), and the ratios
B / A. Both write the same files (the figures off: gnuplot is not what is compared) and
identify the same E, which the script checks.
"""

import argparse
import glob
import os
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

PYTHON_RUN = """
import sys, time
start = time.perf_counter()
import mcrewave
imported = time.perf_counter()
result = mcrewave.identify(sys.argv[1], quiet=True, overrides=["output.figures=false"])
result.write(sys.argv[2], figures=False)
done = time.perf_counter()
print(repr(result.modulus), imported - start, done - imported)
"""


def identified_modulus(folder):
    with open(os.path.join(folder, "summary.yaml"), encoding="utf-8") as file:
        for line in file:
            if line.startswith("identified_modulus:"):
                return float(line.split()[1])
    raise RuntimeError(f"{folder}/summary.yaml names no identified_modulus")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--build", default=os.path.join(ROOT, "build"))
    parser.add_argument("--runs", type=int, default=5)
    parser.add_argument("--config", default="configs/paper_bar.yaml")
    arguments = parser.parse_args()
    binary = os.path.join(arguments.build, "identify", "identify")
    module = arguments.build
    if arguments.runs < 1:
        print("error: --runs must be at least 1", file=sys.stderr)
        return 2
    missing = [] if os.path.exists(binary) else [f"the identify binary {binary}"]
    if not glob.glob(os.path.join(module, "mcrewave.*.so")):
        missing.append(f"the Python module mcrewave in {module}")
    if missing:
        print(f"error: {' and '.join(missing)} missing: build first (bash scripts/build.sh)",
              file=sys.stderr)
        return 2
    environment = dict(os.environ, PYTHONPATH=module)
    folder = tempfile.mkdtemp(prefix="mcrewave_python_overhead_")
    binary_times, python_times, call_times = [], [], []
    for run in range(arguments.runs):
        start = time.perf_counter()
        subprocess.run([binary, "run", arguments.config, "-q", "-o", f"{folder}/binary",
                        "--set", "output.figures=false"], cwd=ROOT, check=True)
        binary_times.append(time.perf_counter() - start)
        start = time.perf_counter()
        done = subprocess.run([sys.executable, "-c", PYTHON_RUN, arguments.config,
                               f"{folder}/python"], cwd=ROOT, env=environment, check=True,
                              capture_output=True, text=True)
        python_times.append(time.perf_counter() - start)
        modulus, _, call = done.stdout.split()
        call_times.append(float(call))
        if float(modulus) != identified_modulus(f"{folder}/binary"):
            print(f"error: run {run + 1}: Python identified E = {modulus} Pa, the binary "
                  f"{identified_modulus(folder + '/binary')!r} Pa", file=sys.stderr)
            return 1
        print(f"run {run + 1}: binary {binary_times[-1]:.3f} s, python process "
              f"{python_times[-1]:.3f} s (identify and write {call_times[-1]:.3f} s)",
              flush=True)
    binary_median = statistics.median(binary_times)
    python_median = statistics.median(python_times)
    call_median = statistics.median(call_times)
    print(f"\n{arguments.config}, {arguments.runs} runs each, E = {modulus} Pa both ways")
    print("| command | median wall time [s] | ratio to the binary |")
    print("|---|---|---|")
    print(f"| identify run (process) | {binary_median:.3f} | 1 |")
    print(f"| python3 with mcrewave (process) | {python_median:.3f} | "
          f"{python_median / binary_median:.3f} |")
    print(f"| mcrewave.identify and write (the calls) | {call_median:.3f} | "
          f"{call_median / binary_median:.3f} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
