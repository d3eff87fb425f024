"""Tests of the Python module mcrewave (python/, docs/python.md), run by ctest.

Each test class is one ctest (tests/CMakeLists.txt), with the module of the build tree
on PYTHONPATH, the identify binary in MCREWAVE_IDENTIFY_BINARY and the checkout in
MCREWAVE_SOURCE_DIR:
  - IdentifyLikeTheBinaryTest: the module's identification is the binary's on the same
    inputs, to the bit (summary.yaml's every line but the wall times and the paths), on
    the bar and on the plate, with the model read from the manifest, built from scipy
    matrices, or the config's, and with the data simulated, from a CSV or from numpy;
  - SimulateLikeTheBinaryTest: simulate gives the CSV the binary writes, to the bit;
  - BadInputTest: bad configs, models and data raise mcrewave.InputError with the
    binary's message, or TypeError for a wrong type;
  - GilTest: a run leaves the interpreter free to run other threads;
  - InterruptTest: Ctrl-C and a progress callback that raises stop a run at once;
  - ResultTest: the arrays are views of the result, the progress lines arrive, and
    Result.write writes the binary's files.
"""

import os
import re
import signal
import subprocess
import tempfile
import threading
import time
import unittest

import numpy as np
import scipy.io
import scipy.sparse

import mcrewave

SOURCE = os.environ.get("MCREWAVE_SOURCE_DIR",
                        os.path.join(os.path.dirname(__file__), "..", ".."))
BINARY = os.environ.get("MCREWAVE_IDENTIFY_BINARY",
                        os.path.join(SOURCE, "build", "identify", "identify"))


def run_binary(*arguments):
    """The identify binary run from the checkout: (exit code, stderr)."""
    done = subprocess.run([BINARY, *arguments], cwd=SOURCE, capture_output=True, text=True,
                          check=False)
    return done.returncode, done.stderr


def comparable(summary_text):
    """summary.yaml without what differs between two runs of the same inputs: the wall
    times, the config's path and the output folder."""
    kept = []
    for line in summary_text.splitlines():
        if re.search(r"wall_time_s:|^# config:|^\s*folder:", line):
            continue
        kept.append(line)
    return "\n".join(kept)


def binary_summary(config, folder, *overrides):
    code, errors = run_binary("run", config, "-q", "-o", folder,
                              *[item for o in overrides for item in ("--set", o)])
    if code != 0:
        raise AssertionError(f"identify run {config} failed: {errors}")
    with open(os.path.join(folder, "summary.yaml"), encoding="utf-8") as file:
        return file.read()


def model_from_scipy(manifest_folder):
    """The plate's coarse model (configs/plate/coarse/model_axial.yaml) built in memory
    from its Matrix Market files with scipy, as another FE package would hand them over,
    not through the manifest reader: (mass, zones, loads, sensors, sensor_kinds)."""
    def read(name):
        return scipy.io.mmread(os.path.join(manifest_folder, name))
    mass = scipy.sparse.csc_matrix(read("M.mtx"))
    zones = [(name, scipy.sparse.csc_matrix(read(f"K_{name}.mtx")), 2e11)
             for name in ("matrix", "inclusion")]
    loads = {"F": np.asarray(read("load_Fx.mtx")).ravel()}
    sensors = {name: scipy.sparse.csr_matrix(read(f"sensor_{name}.mtx"))
               for name in ("uy_tip", "uy_mid", "ux_tip", "exx_root", "exx_mid")}
    kinds = {"exx_root": "strain", "exx_mid": "strain"}
    return mass, zones, loads, sensors, kinds


class IdentifyLikeTheBinaryTest(unittest.TestCase):

    def setUp(self):
        os.chdir(SOURCE)
        self.folder = tempfile.mkdtemp(prefix="mcrewave_python_")

    def test_the_bar_is_the_binarys_to_the_bit(self):
        expected = binary_summary("configs/quick.yaml", self.folder)
        result = mcrewave.identify("configs/quick.yaml", quiet=True)
        self.assertEqual(comparable(result.summary_yaml), comparable(expected))
        self.assertEqual(result.modulus, result.summary["identified_modulus"])
        self.assertEqual(result.structure, "bar")

    def test_overrides_are_the_binarys_set(self):
        expected = binary_summary("configs/quick.yaml", self.folder, "outer.optimizer=ceres",
                                  "data.snr=10")
        from_dict = mcrewave.identify("configs/quick.yaml", quiet=True,
                                      overrides={"outer.optimizer": "ceres", "data.snr": 10})
        from_list = mcrewave.identify("configs/quick.yaml", quiet=True,
                                      overrides=["outer.optimizer=ceres", "data.snr=10"])
        self.assertEqual(comparable(from_dict.summary_yaml), comparable(expected))
        self.assertEqual(comparable(from_list.summary_yaml), comparable(expected))

    def test_a_config_dict_is_the_same_config(self):
        # The quick config's sections as a dict, through the module's own reader of
        # the resolved config (every key), then identified from the dict.
        resolved = mcrewave.resolved_config("configs/quick.yaml")
        self.assertIn("outer", resolved)
        from_dict = mcrewave.identify(resolved, quiet=True)
        from_file = mcrewave.identify("configs/quick.yaml", quiet=True)
        self.assertEqual(from_dict.modulus, from_file.modulus)

    def test_the_plate_from_its_manifest_from_scipy_and_from_numpy_data(self):
        overrides = ["uncertainty.samples=2"]
        expected = binary_summary("configs/plate.yaml", self.folder, *overrides)
        from_config = mcrewave.identify("configs/plate.yaml", quiet=True, overrides=overrides)
        self.assertEqual(comparable(from_config.summary_yaml), comparable(expected))

        # The same model given in code, from the manifest and from scipy matrices: the
        # same moduli to the bit. The truth stays the config's finer mesh.
        manifest = "configs/plate/coarse/model_axial.yaml"
        from_manifest = mcrewave.identify("configs/plate.yaml", mcrewave.Model.from_manifest(
            manifest), quiet=True, overrides=overrides)
        mass, zones, loads, sensors, kinds = model_from_scipy("configs/plate/coarse")
        model = mcrewave.Model(mass, zones, loads, sensors, stiffness_length=0.01, length=0.4,
                               sensor_kinds=kinds, name="the scipy plate")
        from_scipy = mcrewave.identify("configs/plate.yaml", model, quiet=True,
                                       overrides=overrides)
        np.testing.assert_array_equal(from_manifest.moduli, from_config.moduli)
        np.testing.assert_array_equal(from_scipy.moduli, from_config.moduli)
        self.assertEqual(from_scipy.cost, from_config.cost)

        # The data as numpy arrays: the binary's simulated CSV read with numpy, against
        # the binary identifying from that CSV.
        csv = os.path.join(self.folder, "plate.csv")
        code, errors = run_binary("simulate", "configs/plate.yaml", "-q", "-o", csv)
        self.assertEqual(code, 0, errors)
        table = np.genfromtxt(csv, delimiter=",", names=True)
        times = table["t"]
        channels = {name: table[name] for name in table.dtype.names if name != "t"}
        data = mcrewave.Data(channels, time_step=times[1] - times[0], name=csv)
        folder = os.path.join(self.folder, "csv")
        expected = binary_summary("configs/plate.yaml", folder, *overrides, "data.source=csv",
                                  f"data.path={csv}")
        # The record replaces the CSV: data.source csv and data.path its name.
        from_numpy = mcrewave.identify("configs/plate.yaml", data=data, quiet=True,
                                       overrides=overrides)
        self.assertEqual(comparable(from_numpy.summary_yaml), comparable(expected))


class SimulateLikeTheBinaryTest(unittest.TestCase):

    def setUp(self):
        os.chdir(SOURCE)
        self.folder = tempfile.mkdtemp(prefix="mcrewave_python_")

    def check(self, config):
        csv = os.path.join(self.folder, "simulated.csv")
        code, errors = run_binary("simulate", config, "-q", "-o", csv)
        self.assertEqual(code, 0, errors)
        table = np.genfromtxt(csv, delimiter=",", names=True)
        data = mcrewave.simulate(config, quiet=True)
        self.assertEqual(sorted(data.names), sorted(n for n in table.dtype.names if n != "t"))
        for name in data.names:
            # 17 digits in the CSV: the same doubles.
            np.testing.assert_array_equal(data[name], table[name])
        np.testing.assert_array_equal(data.times, table["t"])

    def test_the_bar(self):
        self.check("configs/quick.yaml")

    def test_the_plate(self):
        self.check("configs/plate.yaml")

    def test_a_given_model_is_the_truth_of_its_matrix_keys(self):
        # A model given in code makes the config one of a structure given by matrices:
        # data.truth_moduli applies, and the truth is that model (no manifest read).
        mass, zones, loads, sensors, kinds = model_from_scipy("configs/plate/coarse")
        model = mcrewave.Model(mass, zones, loads, sensors, stiffness_length=0.01, length=0.4,
                               sensor_kinds=kinds, name="the scipy plate")
        config = {"time": {"window": 2e-4, "step": 1e-6},
                  "load": {"duration": 2e-5, "amplitude": 1000},
                  "data": {"truth_moduli": [2e11, 1.4e11], "snr": float("inf")}}
        data = mcrewave.simulate(config, model, quiet=True)
        force = data["F"]
        outputs = model.response([2e11, 1.4e11], force[np.newaxis, :], time_step=1e-6)
        for row, name in enumerate(model.sensor_channels):
            np.testing.assert_array_equal(data[name], outputs[row])
        # And the record given in code needs no data.path.
        with_record = mcrewave.identify({**config, "data": {"source": "csv"}}, model, data,
                                        quiet=True, overrides=["uncertainty.samples=2"])
        # Noise-free data of the model itself, pre-filtered by default: measured 2.9e-4 off.
        np.testing.assert_allclose(with_record.moduli, [2e11, 1.4e11], rtol=3e-3)


class BadInputTest(unittest.TestCase):

    def setUp(self):
        os.chdir(SOURCE)
        self.folder = tempfile.mkdtemp(prefix="mcrewave_python_")

    def assert_same_message(self, binary_arguments, call):
        code, errors = run_binary(*binary_arguments, "-o", os.path.join(self.folder, "out"))
        self.assertEqual(code, 2, errors)
        with self.assertRaises(mcrewave.InputError) as raised:
            call()
        self.assertEqual("error: " + str(raised.exception), errors.strip())
        self.assertFalse(os.path.exists(os.path.join(self.folder, "out")))

    def test_an_unknown_key(self):
        self.assert_same_message(
            ["run", "configs/quick.yaml", "--set", "outer.optimiser=ceres"],
            lambda: mcrewave.identify("configs/quick.yaml", overrides=["outer.optimiser=ceres"]))

    def test_a_value_out_of_range(self):
        self.assert_same_message(
            ["run", "configs/quick.yaml", "--set", "time.theta=0.2"],
            lambda: mcrewave.identify("configs/quick.yaml", overrides=["time.theta=0.2"]))

    def test_a_missing_config_file(self):
        self.assert_same_message(["run", "configs/no_such.yaml"],
                                 lambda: mcrewave.identify("configs/no_such.yaml"))

    def test_a_csv_the_config_does_not_fit(self):
        csv = os.path.join(self.folder, "short.csv")
        with open(csv, "w", encoding="utf-8") as file:
            file.write("t,u0,uL,f0,fL\n0,0,0,0,0\n1e-6,0,1e-9,1,1\n")
        self.assert_same_message(
            ["run", "configs/quick.yaml", "--set", "data.source=csv", "--set", f"data.path={csv}"],
            lambda: mcrewave.identify("configs/quick.yaml",
                                      overrides=["data.source=csv", f"data.path={csv}"]))

    def test_a_config_dict_names_the_key(self):
        # The dict is read as one line of YAML: line 1.
        with self.assertRaisesRegex(mcrewave.InputError,
                                    r"^the config dict:1: unknown key 'outer\.optimiser'; did you "
                                    r"mean 'outer\.optimizer'\?$"):
            mcrewave.identify({"outer": {"optimiser": "ceres"}})
        with self.assertRaisesRegex(mcrewave.InputError, r"time\.theta"):
            mcrewave.identify({"time": {"theta": 0.2}})

    def test_a_model_that_is_not_one(self):
        n = 4
        mass = scipy.sparse.identity(n, format="csc")
        stiffness = scipy.sparse.diags([2.0] * n, format="csc")
        loads = {"F": np.eye(n)[3]}
        sensors = {"u": np.eye(n)[3]}

        def model(**changes):
            arguments = dict(mass=mass, zones=[("all", stiffness, 1e9)], loads=loads,
                             sensors=sensors, stiffness_length=1.0, length=1.0)
            arguments.update(changes)
            positional = [arguments.pop(k) for k in ("mass", "zones", "loads", "sensors")]
            return mcrewave.Model(*positional, **arguments)

        self.assertEqual(model().dofs, n)
        lopsided = scipy.sparse.csc_matrix(np.triu(np.ones((n, n))) + np.eye(n))
        with self.assertRaisesRegex(mcrewave.InputError, r"^model: the mass matrix: not symmetric"):
            model(mass=lopsided)
        with self.assertRaisesRegex(mcrewave.InputError, r"load 'F'.* 3 .*4 dofs|load 'F'"):
            model(loads={"F": np.ones(3)})
        with self.assertRaisesRegex(mcrewave.InputError, r"channel 'F'"):
            model(sensors={"F": np.eye(n)[0]})
        with self.assertRaisesRegex(mcrewave.InputError, r"not a finite number"):
            model(zones=[("all", stiffness * np.nan, 1e9)])
        with self.assertRaisesRegex(mcrewave.InputError, r"stiffness_length"):
            model(stiffness_length=-1.0)
        with self.assertRaises(TypeError):
            model(mass="M.mtx")

    def test_data_that_are_not_a_record(self):
        with self.assertRaisesRegex(mcrewave.InputError, r"^the data: channel 'uL': sample 1 "):
            mcrewave.Data({"uL": [0.0, np.nan, 1.0]}, time_step=1e-6)
        with self.assertRaisesRegex(mcrewave.InputError, r"channel 'fL': 2 samples"):
            mcrewave.Data({"uL": [0.0, 1.0, 2.0], "fL": [0.0, 1.0]}, time_step=1e-6)
        with self.assertRaisesRegex(mcrewave.InputError, r"time_step"):
            mcrewave.Data({"uL": [0.0, 1.0]}, time_step=0.0)
        # A record without the bar's f0 column: the binary's header message.
        record = mcrewave.Data({"u0": np.zeros(301), "uL": np.ones(301), "fL": np.ones(301)},
                               time_step=1.44e-6, name="my record")
        with self.assertRaisesRegex(mcrewave.InputError,
                                    r"^my record: the header 't,u0,uL,fL' lacks the column 'f0'"):
            mcrewave.identify("configs/quick.yaml", data=record)
        # The plate's record without its force channel.
        plate = mcrewave.Data({"ux_tip": np.zeros(201)}, time_step=1e-6, name="my record")
        with self.assertRaisesRegex(mcrewave.InputError,
                                    r"^my record: the record lacks the column 'F'"):
            mcrewave.identify("configs/plate.yaml", data=plate)
        with self.assertRaises(TypeError):
            mcrewave.identify("configs/quick.yaml", data={"uL": [0.0, 1.0]})




class GilTest(unittest.TestCase):

    def test_a_run_leaves_other_threads_free(self):
        os.chdir(SOURCE)
        done = threading.Event()
        outcome = {}

        def identify():
            outcome["result"] = mcrewave.identify("configs/plate.yaml", quiet=True,
                                                  overrides=["uncertainty.samples=2"])
            done.set()

        worker = threading.Thread(target=identify)
        start = time.perf_counter()
        worker.start()
        counted = 0
        while not done.is_set():
            counted += 1
        worker.join()
        seconds = time.perf_counter() - start
        self.assertTrue(outcome["result"].success)
        # With the GIL held by the run this loop would stall for its whole length (a few
        # counts); released, it counts millions a second (measured: 8.7e6 a second beside
        # the run, on two cores).
        self.assertGreater(seconds, 0.5)
        self.assertGreater(counted / seconds, 1e6)


    def test_runs_at_once_from_two_threads_give_one_runs_bits(self):
        os.chdir(SOURCE)
        alone = mcrewave.identify("configs/quick.yaml", quiet=True)
        results = [None, None]

        def identify(index):
            results[index] = mcrewave.identify("configs/quick.yaml", quiet=True,
                                               progress=lambda line: None)

        workers = [threading.Thread(target=identify, args=(i,)) for i in range(2)]
        for worker in workers:
            worker.start()
        for worker in workers:
            worker.join()
        for result in results:
            self.assertEqual(result.modulus, alone.modulus)
            self.assertEqual(result.cost, alone.cost)
        # The logger is the process's again: a new call's lines reach its own callable.
        lines = []
        mcrewave.identify("configs/quick.yaml", progress=lines.append)
        self.assertTrue(lines)


class InterruptTest(unittest.TestCase):

    def setUp(self):
        os.chdir(SOURCE)

    def test_ctrl_c_stops_a_run_at_once(self):
        # Unpreconditioned on the gauge plate: minutes if not stopped.
        timer = threading.Timer(1.0, lambda: os.kill(os.getpid(), signal.SIGINT))
        start = time.perf_counter()
        timer.start()
        with self.assertRaises(KeyboardInterrupt):
            mcrewave.identify("configs/plate_zones_gauges.yaml", quiet=True,
                              overrides=["inner.preconditioner=none"])
        seconds = time.perf_counter() - start
        timer.join()
        # Measured: 1.0 s (the signal at 1 s, the run ended within one inner iteration).
        self.assertLess(seconds, 10.0)
        # Python's own handler is back: the next Ctrl-C is a KeyboardInterrupt in Python.
        self.assertIs(signal.getsignal(signal.SIGINT), signal.default_int_handler)

    def test_a_progress_callback_that_raises_stops_the_run(self):
        class Enough(Exception):
            pass

        lines = []

        def progress(line):
            lines.append(line)
            if len(lines) == 3:
                raise Enough(line)

        start = time.perf_counter()
        with self.assertRaises(Enough):
            mcrewave.identify("configs/plate_zones_gauges.yaml", progress=progress,
                              overrides=["inner.preconditioner=none"])
        self.assertLess(time.perf_counter() - start, 30.0)
        self.assertEqual(len(lines), 3)


class ResultTest(unittest.TestCase):

    def setUp(self):
        os.chdir(SOURCE)
        self.folder = tempfile.mkdtemp(prefix="mcrewave_python_")

    def test_progress_lines_arrive_and_write_gives_the_binarys_files(self):
        lines = []
        result = mcrewave.identify("configs/quick.yaml", progress=lines.append,
                                   overrides=["output.figures=false"])
        self.assertTrue(any("evaluation" in line for line in lines), lines[:5])
        written = result.write(os.path.join(self.folder, "python"), figures=False)
        expected = binary_summary("configs/quick.yaml", os.path.join(self.folder, "binary"),
                                  "output.figures=false")
        names = sorted(os.path.basename(path) for path in written)
        self.assertEqual(names, sorted(os.listdir(os.path.join(self.folder, "binary"))))
        with open(os.path.join(self.folder, "python", "summary.yaml"), encoding="utf-8") as file:
            self.assertEqual(comparable(file.read()), comparable(expected))

    def test_arrays_are_read_only_views_of_the_result(self):
        result = mcrewave.identify("configs/plate.yaml", quiet=True,
                                   overrides=["uncertainty.samples=2"])
        moduli = result.moduli
        self.assertEqual(moduli.shape, (2,))
        self.assertFalse(moduli.flags.writeable)
        self.assertFalse(moduli.flags.owndata)
        # Within 3 % of the truth (measured: -2.4 % and -1.2 %, the model's coarser mesh).
        np.testing.assert_allclose(moduli, result.truth_moduli, rtol=0.03)
        maps = result.error_maps
        self.assertEqual(maps["zone"].shape, (2,))
        self.assertEqual(maps["element"].shape, (144,))
        self.assertEqual(result.model_outputs.shape, (5, 201))
        self.assertEqual(result.zone_names, ["matrix", "inclusion"])
        # The refinement's evaluations (the scans' are counted apart).
        self.assertEqual(len(result.evaluations), result.summary["optimizer"]["evaluations"])
        self.assertEqual(result.evaluations[-1]["moduli"].shape, (2,))
        del result
        # The views keep the result alive.
        self.assertEqual(moduli.shape, (2,))
        self.assertTrue(np.all(np.isfinite(moduli)))

    def test_a_failed_identification_raises_with_its_result(self):
        with self.assertRaises(mcrewave.IdentificationError) as raised:
            mcrewave.identify("configs/quick.yaml", quiet=True,
                              overrides=["outer.upper_bound=1.9e11", "outer.initial=1.5e11"])
        code, errors = run_binary("run", "configs/quick.yaml", "-q", "--set",
                                  "outer.upper_bound=1.9e11", "--set", "outer.initial=1.5e11", "-o",
                                  os.path.join(self.folder, "out"))
        self.assertEqual(code, 1)
        self.assertEqual("error: " + str(raised.exception), errors.strip())
        self.assertFalse(raised.exception.result.success)


if __name__ == "__main__":
    unittest.main()
