"""Talus from Python: scenes, ensembles, scores and the calibration objective (docs/python.md).

The classes come from the compiled core, which runs the same C++ library calls as the ``talus``
program: the same scene and seed give the same numbers, bit for bit, as ``talus simulate``,
``talus validate`` and ``talus calibrate``, for any number of threads. C++ runs with the GIL
released, so other Python threads go on meanwhile; Ctrl-C stops a run.

Scene
    ``Scene.load(path)`` or ``Scene.from_dict(values)``; ``set_ground``, ``set_solver``, ``rocks``,
    ``seed``; ``run_rock(i)`` (one trajectory as arrays) and ``simulate()`` (per-rock arrays under
    rocks.csv's column names, rasters as arrays with their geotransform and CRS).
Event
    ``Event.load(path)``; ``validate()`` returns what scores.json holds.
Calibration
    ``Calibration.load(path, holdout=..., folds=...)``; ``evaluate(values)`` is the objective
    ``talus calibrate`` minimises; ``run()`` runs the built-in calibration.
InputError
    Bad input, with the message the command line prints (file, line, key, reason).
"""

from ._core import Calibration, Event, InputError, Scene, __version__

__all__ = ["Calibration", "Event", "InputError", "Scene", "__version__"]
