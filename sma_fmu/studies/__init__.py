"""Design studies: the study API, sweeps and Monte Carlo on Dask, gain tuning, the batch engine.

- :mod:`~sma_fmu.studies.runs`: run a scenario with overrides on the library, FMU or batch
  path; time series as a pandas DataFrame, metrics as a record (:func:`run`, :func:`run_many`);
- :mod:`~sma_fmu.studies.overrides`: scenarios with fields overridden (``"section.key"``);
- :mod:`~sma_fmu.studies.batch`: the subpackage of the batch engine, N closed loops in lock-step
  with numpy (:func:`run_batch`; its throughput: :mod:`~sma_fmu.studies.batch_benchmark`);
- :mod:`~sma_fmu.studies.spec`, :mod:`~sma_fmu.studies.design`, :mod:`~sma_fmu.studies.sweep`,
  :mod:`~sma_fmu.studies.results`: study specs, their designs, ``sma-fmu sweep``, its results;
- :mod:`~sma_fmu.studies.tuning`: ``sma-fmu tune`` (its criterion:
  :mod:`~sma_fmu.studies.criterion`; its reports: :mod:`~sma_fmu.studies.tuning_report`).
See docs/studies.md.
"""
from sma_fmu.studies.batch import BatchUnsupported, run_batch
from sma_fmu.studies.overrides import StudyError, template
from sma_fmu.studies.runs import StudyRun, metrics_record, run, run_many, scenario, timeseries_frame

__all__ = ["BatchUnsupported", "StudyError", "StudyRun", "metrics_record", "run", "run_batch",
           "run_many", "scenario", "template", "timeseries_frame"]
