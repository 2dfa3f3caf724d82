"""The batch engine: N closed loops in lock-step with numpy, equal to the scalar library path.

- :mod:`~.engine`: the loop of spec section 11 over N runs (:func:`run_batch`,
  :func:`run_batches`), what it refuses (:func:`unsupported_reason`, :class:`BatchUnsupported`);
- :mod:`~.inputs`: per-run constants and the open-loop signals, known before the start;
- :mod:`~.plant`, :mod:`~.feedforward` (with :mod:`~.minor_loops`), :mod:`~.pwm`: N plants,
  N compensators, N PWM drivers, each a vectorised twin of its runtime stepper;
- :mod:`~.metrics`: the tracking metrics, accumulated chunk by chunk.
See docs/studies.md.
"""
from sma_fmu.studies.batch.engine import (RECORDS, BatchRun, BatchUnsupported, run_batch, run_batches,
                                          unsupported_reason)

__all__ = ["RECORDS", "BatchRun", "BatchUnsupported", "run_batch", "run_batches", "unsupported_reason"]
