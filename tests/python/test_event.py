"""talus.Event: an event's validation gives what talus validate writes in scores.json."""

import json

import pytest

import talus
from conftest import TSCHAMUT, run_talus


def without_timing(scores):
    """scores.json without what depends on the machine (times, threads)."""
    scores = json.loads(json.dumps(scores))
    for key in ("wall_time_s", "threads"):
        scores.get("run", {}).pop(key, None)
        scores.pop(key, None)
    return scores


def test_validation_is_the_programs(tmp_path):
    event_path = TSCHAMUT / "event.toml"
    out = tmp_path / "out"
    run_talus("validate", event_path, "--out", out, "--rocks", "2", "--threads", "2")
    event = talus.Event.load(event_path)
    event.scene.rocks = 2
    scores = event.validate(threads=1)
    with open(out / "scores.json") as f:
        stored = json.load(f)
    assert without_timing(scores) == without_timing(stored)
    assert scores["observations"], "the event has scored observations"


def test_editing_the_events_scene_changes_what_is_validated():
    event = talus.Event.load(TSCHAMUT / "event.toml")
    event.scene.rocks = 1
    assert event.scene.rocks == 1
    with pytest.raises(talus.InputError, match="threads"):
        event.validate(threads=-1)


def test_bad_event_raises_with_the_programs_message(tmp_path):
    bad = tmp_path / "event.toml"
    bad.write_text(f'scene = "{TSCHAMUT / "scene.toml"}"\n[[observations]]\nkind = "runouts"\n'
                   f'file = "{TSCHAMUT / "observed_deposition.csv"}"\n')
    with pytest.raises(talus.InputError) as raised:
        talus.Event.load(bad)
    done = run_talus("validate", bad, "--out", tmp_path / "out", check=False)
    assert done.returncode == 2
    assert done.stderr.strip() == f"talus validate: {raised.value}"
