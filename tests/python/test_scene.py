"""talus.Scene: loading, edits, one rock and an ensemble, the same bits as talus simulate."""

import csv
import subprocess
import threading
import time

import h5py
import numpy as np
import pytest

import talus
from conftest import SOURCE, run_talus


def test_load_describes_the_scene():
    scene = talus.Scene.load(SOURCE / "cases" / "ramp40" / "scene.toml")
    assert scene.rocks == 1000 and scene.seed == 1 and scene.total_rocks == 1000
    assert scene.solver["dt_s"] == 0.002
    assert "medium_hard" in scene.ground
    assert scene.ground["medium_hard"]["mu_min"] > 0
    assert len(scene.geotransform) == 6


def test_bad_input_raises_with_the_programs_message(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text((SOURCE / "cases" / "ramp40" / "scene.toml").read_text()
                   .replace("rocks = 1000", "rocks = -3"))
    with pytest.raises(talus.InputError) as raised:
        talus.Scene.load(bad)
    done = run_talus("simulate", bad, "--out", tmp_path / "out", check=False)
    assert done.returncode == 2
    assert done.stderr.strip() == f"talus simulate: {raised.value}"
    assert isinstance(raised.value, ValueError)
    with pytest.raises(talus.InputError, match="not found"):
        talus.Scene.load(tmp_path / "missing.toml")


def test_edits_are_checked_and_undone_when_they_fail(small_ramp):
    scene = talus.Scene.load(small_ramp)
    scene.set_ground("medium_hard", mu_min=0.4, kappa=3.0)
    assert scene.ground["medium_hard"]["mu_min"] == 0.4
    with pytest.raises(talus.InputError, match="mu_min"):
        scene.set_ground("medium_hard", mu_min=-1.0)
    assert scene.ground["medium_hard"]["mu_min"] == 0.4  # undone
    with pytest.raises(talus.InputError, match="no ground category 'meadow'"):
        scene.set_ground("meadow", mu_min=0.3)
    with pytest.raises(talus.InputError, match="no such field"):
        scene.set_ground("medium_hard", friction=0.3)
    with pytest.raises(talus.InputError, match="finite"):
        scene.set_ground("medium_hard", mu_min=float("nan"))
    with pytest.raises(talus.InputError, match="dt_s"):
        scene.set_solver(dt_s=-0.001)
    assert scene.solver["dt_s"] == 0.002
    with pytest.raises(talus.InputError):
        scene.rocks = 0
    assert scene.rocks == 6


def test_from_dict_is_the_same_scene_as_the_file(small_ramp):
    import tomllib
    values = tomllib.loads(small_ramp.read_text())
    built = talus.Scene.from_dict(values, path=small_ramp)
    loaded = talus.Scene.load(small_ramp)
    a = built.simulate(threads=1, rasters=False)["rocks"]
    b = loaded.simulate(threads=1, rasters=False)["rocks"]
    assert all(np.array_equal(a[k], b[k]) for k in a)
    values["release"]["rocks"] = "many"
    with pytest.raises(talus.InputError, match="rocks"):
        talus.Scene.from_dict(values)


def test_ensemble_is_the_programs_to_the_bit(small_ramp, tmp_path):
    out = tmp_path / "out"
    run_talus("simulate", small_ramp, "--out", out, "--threads", "2")
    scene = talus.Scene.load(small_ramp)
    result = scene.simulate(threads=1, trajectories=True)
    rocks = result["rocks"]

    # rocks.csv: every column, as the program formats it.
    with open(out / "rocks.csv") as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == len(rocks["rock"]) == 6
    for i, row in enumerate(rows):
        for name, text in row.items():
            value = rocks[name][i]
            if isinstance(value, str):
                assert value == text, name
            elif np.issubdtype(type(value), np.integer):
                assert str(value) == text, name
            else:
                assert f"{value:.10g}" == text, name

    # trajectories.h5: every sample of every rock, bit for bit.
    with h5py.File(out / "trajectories.h5") as h5:
        first, count = h5["rocks/first_sample"][:], h5["rocks/sample_count"][:]
        for i, trajectory in enumerate(result["trajectories"]):
            span = slice(first[i], first[i] + count[i])
            for name in ("t", "position", "quaternion", "velocity", "angular_velocity", "scar"):
                stored = h5["samples/" + name][span]
                assert np.array_equal(stored.reshape(trajectory[name].shape), trajectory[name]), name
            assert np.array_equal(h5["samples/contact"][span].reshape(-1) == 1,
                                  trajectory["contact"])

    # The rasters: the GeoTIFFs' values (float32; int32 counts) and geotransform.
    assert result["rasters"], "the scene asks for rasters"
    for name, layer in result["rasters"].items():
        raw = tmp_path / (name + ".bin")
        subprocess.run(["gdal_translate", "-q", "-of", "ENVI", out / (name + ".tif"), raw],
                       check=True)
        stored = np.fromfile(raw, dtype=layer["values"].dtype).reshape(layer["values"].shape)
        assert layer["values"].dtype == (np.int32 if layer["unit"] == "count" else np.float32)
        assert np.array_equal(stored, layer["values"]), name
        info = subprocess.run(["gdalinfo", "-json", out / (name + ".tif")], check=True,
                              capture_output=True, text=True).stdout
        import json
        assert tuple(json.loads(info)["geoTransform"]) == result["geotransform"]
    assert result["counts"]["rocks"] == 6


def test_one_rock_is_the_ensembles_rock(small_ramp):
    scene = talus.Scene.load(small_ramp)
    ensemble = scene.simulate(threads=2, trajectories=True, rasters=False)
    one = scene.run_rock(3)
    assert np.array_equal(one["position"], ensemble["trajectories"][3]["position"])
    assert one["result"]["runout_m"] == ensemble["rocks"]["runout_m"][3]
    assert one["t"][0] == 0 and one["quaternion"].shape[1] == 4
    with pytest.raises(talus.InputError, match="rock 6"):
        scene.run_rock(6)


def test_any_thread_count_gives_the_same_bits(small_ramp):
    scene = talus.Scene.load(small_ramp)
    one = scene.simulate(threads=1)
    two = scene.simulate(threads=2)
    for name in one["rocks"]:
        assert np.array_equal(one["rocks"][name], two["rocks"][name]), name
    for name in one["rasters"]:
        assert np.array_equal(one["rasters"][name]["values"], two["rasters"][name]["values"])


def test_other_python_threads_run_while_rocks_run(small_ramp):
    """With the GIL held during the run a counting thread could not advance at all."""
    scene = talus.Scene.load(small_ramp)
    scene.rocks = 40
    ticks = []
    stop = threading.Event()

    def count():
        while not stop.is_set():
            ticks.append(time.perf_counter())
            time.sleep(0.001)

    counter = threading.Thread(target=count)
    counter.start()
    try:
        time.sleep(0.05)
        begin = time.perf_counter()
        scene.simulate(threads=1, rasters=False)
        end = time.perf_counter()
    finally:
        stop.set()
        counter.join()
    during = sum(begin < t < end for t in ticks)
    assert during >= 10, f"{during} ticks in {end - begin:.2f} s of simulation"


def test_ctrl_c_stops_a_run(small_ramp):
    """SIGINT during a long ensemble raises KeyboardInterrupt promptly, as Ctrl-C in a notebook."""
    import os
    import signal
    import sys
    script = f"""
import sys, talus
scene = talus.Scene.load({str(small_ramp)!r})
scene.rocks = 100000
print("running", flush=True)
try:
    scene.simulate(threads=1, rasters=False)
except KeyboardInterrupt:
    print("interrupted", flush=True)
    sys.exit(3)
"""
    child = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE, text=True,
                             env=dict(os.environ))
    assert child.stdout.readline().strip() == "running"
    time.sleep(1.0)
    child.send_signal(signal.SIGINT)
    try:
        out, _ = child.communicate(timeout=30)
    finally:
        child.kill()
    assert child.returncode == 3 and "interrupted" in out


def test_barrier_and_line_results_are_the_programs(tmp_path):
    """What rocks did at the tirol case's 500 kJ net and its evaluation lines: barriers.csv's and
    evaluation_lines.csv's rows, from Python."""
    scene_path = SOURCE / "cases" / "tirol" / "scene_net.toml"
    out = tmp_path / "out"
    run_talus("simulate", scene_path, "--out", out, "--rocks", "30", "--threads", "2")
    scene = talus.Scene.load(scene_path)
    scene.rocks = 30
    result = scene.simulate(threads=2, rasters=False)
    with open(out / "barriers.csv") as f:
        rows = list(csv.DictReader(f))
    barriers = result["barriers"]
    assert len(rows) == len(barriers["rock"]) > 0
    for i, row in enumerate(rows):
        assert row["barrier"] == barriers["barrier"][i]
        assert row["outcome"] == barriers["outcome"][i]
        assert int(row["rock"]) == barriers["rock"][i]
        for name in ("energy_J", "energy_after_J", "passing_height_m", "t_s", "speed_m_s"):
            assert f"{barriers[name][i]:.10g}" == row[name], name
    # The evaluation lines' crossings: evaluation_lines.csv's rows.
    with open(out / "evaluation_lines.csv") as f:
        rows = list(csv.DictReader(f))
    lines = result["lines"]
    assert len(rows) == len(lines["rock"]) > 0
    for i, row in enumerate(rows):
        assert row["line"] == lines["line"][i] and int(row["rock"]) == lines["rock"][i]
        assert int(row["crossings"]) == lines["crossings"][i]
        for name in ("t_s", "speed_m_s", "energy_J", "bounce_height_m", "com_height_m"):
            assert f"{lines[name][i]:.10g}" == row[name], name
        assert f"{lines['position_m'][i][0]:.10g}" == row["x_m"]
    stopped = result["rocks"]["end"] == "barrier"
    assert list(result["rocks"]["end_barrier"][stopped]) == ["lower net"] * int(stopped.sum())
    assert result["counts"]["ends"]["barrier"] == int(stopped.sum())
