"""The thesis's grasping experiment (4.2.4, Table 4.4) as a benchmark: objects x trials x planners.

* :mod:`~contourgrasp.sim.bench.config` -- :class:`Bench` (what to run), object sets and splits, the thesis's objects, rates and labels
* :mod:`~contourgrasp.sim.bench.parallel` -- where trials run: this process, worker processes, Ray tasks
* :mod:`~contourgrasp.sim.bench.run` -- :func:`run_bench`, progress, reruns of trials for the pictures
* :mod:`~contourgrasp.sim.bench.stats` -- success rates and their Wilson intervals
* :mod:`~contourgrasp.sim.bench.report` -- Markdown tables, trial records, :func:`write_outputs`
* :mod:`~contourgrasp.sim.bench.journal` -- ``trials.jsonl``, written as trials finish, for ``--resume``
* :mod:`~contourgrasp.sim.bench.figures` -- matplotlib figures (imported only when they are drawn)

Example::

    from contourgrasp.sim import bench
    setup = bench.Bench(objects=bench.thesis_objects(["can"]), trials=2)
    with bench.executor(setup, workers=2) as run:
        results = bench.run_bench(setup, execute=run)
    print("\\n".join(bench.rates_table(setup, results)))
"""

from .config import (LABELS, OBJECT_SETS, SHORT_CAUSES, THESIS_SUCCESS, Bench, BenchTrial, label, load_object,
                     object_names, resolve_objects, thesis_objects)
from .journal import JOURNAL, Journal, digest, resume, settings
from .parallel import RAY_INSTALL, cores, executor, processes, ray_tasks, serial, trial_task
from .report import (CHART, FAILURES, MOSAIC_TILES, PICTURE, TABLE, TRIALS, ablation_table, cause_table, markdown,
                     object_table, picked_failures, planner_notes, rates_table, split_cause_table, split_markdown,
                     split_table, trial_from_dict, trial_table, trial_to_dict, write_outputs)
from .run import VIEW_DISTANCE, VIEW_ELEVATION, Snapshot, console_progress, picked_trials, run_bench, snapshot
from .stats import WILSON_Z, records, sort_planner, success_rates, thesis_rates, wilson_interval

__all__ = [
    "Bench", "BenchTrial", "CHART", "FAILURES", "JOURNAL", "Journal", "LABELS", "MOSAIC_TILES", "OBJECT_SETS",
    "PICTURE", "RAY_INSTALL", "SHORT_CAUSES", "Snapshot", "TABLE", "THESIS_SUCCESS", "TRIALS", "VIEW_DISTANCE",
    "VIEW_ELEVATION", "WILSON_Z", "ablation_table", "cause_table", "console_progress", "cores", "digest", "executor",
    "label", "load_object", "markdown", "object_names", "object_table", "picked_failures", "picked_trials",
    "planner_notes", "processes", "ray_tasks", "rates_table", "records", "resolve_objects", "resume", "run_bench",
    "serial", "settings", "snapshot", "sort_planner", "split_cause_table", "split_markdown", "split_table",
    "success_rates", "thesis_objects", "thesis_rates", "trial_from_dict", "trial_table", "trial_task",
    "trial_to_dict", "wilson_interval", "write_outputs",
]
