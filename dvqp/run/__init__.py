"""The run level: what is done with a whole scene, on top of the step and the motion.

- :mod:`dvqp.run.planning` — planning a scene with a named backend (:func:`plan`) and
  checking the run (:func:`check_run`);
- :mod:`dvqp.run.comparison` — comparing backends on the same scenes (the rows of
  ``dvqp compare`` and ``dvqp bench``);
- :mod:`dvqp.run.qp_export` — exporting every QP of a run to files (``dvqp export-qps``);
- :mod:`dvqp.run.sample_checks` — the report's checks on a run's saved samples (worst limit
  excess, final tracking error);
- :mod:`dvqp.run.table_text` — result rows as table text and CSV.
"""
