"""talus.Calibration: the objective talus calibrate minimises, to the bit, from Python; the
built-in calibration through the same call; threads with the GIL released."""

import concurrent.futures
import csv
import json

import numpy as np
import pytest

import talus
from conftest import run_talus


def history_rows(text):
    return list(csv.DictReader(text.splitlines()))


def test_objective_and_calibration_are_the_programs(small_calibration, tmp_path):
    out = tmp_path / "out"
    run_talus("calibrate", small_calibration, "--out", out, "--threads", "2")
    with open(out / "history.csv") as f:
        program = history_rows(f.read())

    calibration = talus.Calibration.load(small_calibration, threads=1)
    assert [p["name"] for p in calibration.parameters] == ["medium.mu_min", "medium.kappa"]
    assert all(p["prior"] is None for p in calibration.parameters)  # none stated
    # The fit starts at the scene's values: its first evaluation is the objective there.
    assert program[0]["start"] == "0"
    first = calibration.evaluate_unit(calibration.start_unit)
    assert first["value"] == float(program[0]["objective"])
    assert first["data"] == float(program[0]["data"])
    assert first["kind_scores"]["runout"] == float(program[0]["score_runout"])

    # The built-in calibration through the call the program makes: the same path, bit for bit.
    result = calibration.run()
    python = history_rows(result["history_csv"])
    assert len(python) == len(program)
    for mine, theirs in zip(python, program):
        for key in theirs:
            if key != "wall_time_s":
                assert mine[key] == theirs[key], key
    with open(out / "ground_table.toml") as f:
        assert result["ground_table_toml"] == f.read()
    assert result["calibration"]["evaluations"] == len(program)


def test_values_and_unit_coordinates(small_calibration):
    calibration = talus.Calibration.load(small_calibration)
    values = np.array([0.5, 2.0])
    u = calibration.to_unit(values)
    assert np.allclose(calibration.to_values(u), values, rtol=1e-14)
    assert calibration.ground_table(values)["medium"]["mu_min"] == pytest.approx(0.5, rel=1e-14)
    outside = calibration.evaluate(np.array([5.0, 2.0]))  # mu_min above its upper bound
    assert not outside["feasible"] and outside["rocks"] == 0 and np.isfinite(outside["value"])
    with pytest.raises(talus.InputError, match="expected a vector of 2"):
        calibration.evaluate(np.array([0.5]))


def test_evaluations_from_several_threads_are_those_of_one(small_calibration):
    calibration = talus.Calibration.load(small_calibration, threads=1)
    points = [np.array([0.3, 1.0]), np.array([0.6, 4.0]), np.array([0.9, 0.5])]
    alone = [calibration.evaluate(p)["value"] for p in points]
    with concurrent.futures.ThreadPoolExecutor(max_workers=3) as pool:
        together = list(pool.map(lambda p: calibration.evaluate(p)["value"], points))
    assert together == alone


def test_bad_calibration_input(small_calibration, tmp_path):
    with pytest.raises(talus.InputError, match="--holdout: 'nope' is not a run"):
        talus.Calibration.load(small_calibration, holdout="nope")
    bad = tmp_path / "bad.toml"
    bad.write_text(small_calibration.read_text().replace('field = "kappa"', 'field = "kapa"'))
    with pytest.raises(talus.InputError) as raised:
        talus.Calibration.load(bad)
    done = run_talus("calibrate", bad, "--out", tmp_path / "out", check=False)
    assert done.returncode == 2
    assert done.stderr.strip() == f"talus calibrate: {raised.value}"


def test_a_parameters_prior_is_read_and_priced(small_calibration, tmp_path):
    text = small_calibration.read_text()
    text = text.replace('upper = 1.2\n', 'upper = 1.2\nprior = { mean = 0.5, sd = 0.1 }\n', 1)
    text = text.replace('[objective]\n', '[objective]\nprior_weight = 0.2\n', 1)
    path = tmp_path / "with_prior.toml"
    path.write_text(text)
    calibration = talus.Calibration.load(path, threads=2)
    assert calibration.parameters[0]["prior"] == {"kind": "normal", "mean": 0.5, "sd": 0.1}
    assert calibration.parameters[1]["prior"] is None  # kappa stays free: prior_reference "none"
    start = calibration.start  # the scene's mu_min (Table 1 medium, 0.35)
    e = calibration.evaluate_unit(calibration.start_unit)
    assert e["prior"] == pytest.approx(0.2 * ((start[0] - 0.5) / 0.1) ** 2, rel=1e-12)
    assert e["value"] == pytest.approx(e["data"] + e["prior"], rel=1e-12)


def test_uncertainty_at_a_point_is_the_programs_at_its_optimum(small_calibration, tmp_path):
    # talus calibrate's sandwich covariance at its optimum, with the file's fixed step, and
    # Calibration.uncertainty_unit at that optimum's unit coordinates: the same evaluations, so the
    # same numbers to the bit (the fit is one BOBYQA start: its best point is the optimum).
    text = small_calibration.read_text().replace("[uncertainty]\nenabled = false",
                                                 "[uncertainty]\nfd_step = 0.05")
    assert "fd_step = 0.05" in text
    path = tmp_path / "with_uncertainty.toml"
    path.write_text(text)
    out = tmp_path / "out"
    run_talus("calibrate", path, "--out", out, "--threads", "2")
    with open(out / "calibration.json") as f:
        program = json.load(f)
    theirs = program["uncertainty"]
    assert theirs["finite_difference_step"] == 0.05

    calibration = talus.Calibration.load(path, threads=2)
    starts = program["starts"]
    best = min(starts, key=lambda s: s["best_objective"])["best"]
    mine = calibration.uncertainty_unit(np.array(best))
    for key in ("names", "values", "standard_error", "standard_error_unit", "correlation",
                "covariance", "identified", "weak", "computed", "rank_deficient", "note",
                "finite_difference_step", "stationary_located", "offset_unit",
                "stationary_values"):
        assert mine[key] == theirs[key], key
    assert "bootstrap" not in mine and "seeds" not in mine
    assert mine["names"] == ["medium.mu_min", "medium.kappa"]
    assert mine["report"]

    # By values, with a step of its own: that step, and the errors of the same parameters.
    other = calibration.uncertainty(np.array(theirs["values"]), fd_step=0.1)
    assert other["finite_difference_step"] == 0.1
    assert len(other["standard_error"]) == 2

    with pytest.raises(talus.InputError, match="fd_step"):
        calibration.uncertainty(np.array(theirs["values"]), fd_step=0.5)
    with pytest.raises(talus.InputError, match="medium.mu_min: the point is outside"):
        calibration.uncertainty(np.array([5.0, 2.0]))
