"""The isobaric fit: the constant-load model identified from a lab's thermal-cycling files.

The path from a lab's test to FMUs: ``sma-fmu fit isobaric FILE... --load KG`` writes
``identified.toml``, which ``sma-fmu build --model`` turns into FMUs (docs/identification.md).

- :mod:`~.files`: read lab files (columns, units, preamble) into branches and cycles
  (:func:`read_isobaric`), splitting them with :mod:`~.cycles`;
- :mod:`~.table` (quoted cells and rows, separators), :mod:`~.columns` (which quantity a
  column holds, a strain given twice), :mod:`~.stress` (a stress column's load ramp, limit
  and spread), :mod:`~.timebase` (time stamps repeated at their resolution), :mod:`~.end_step`
  (a strain step at a file's start or end), :mod:`sma_fmu.identification.workbook` (a
  workbook's sheets as files): the pieces of reading; :mod:`~.missing`: why a number is
  missing, named once;
- :mod:`~.fit`: the fit of parameters, temperature profile and lag (:func:`fit_isobaric`):
  a first fit at the thermocouple's profile (:mod:`~.first_fit`) that chooses the structure
  (:mod:`~.structure`), then the joint fit; on :mod:`~.terms` (the model with its optional
  terms, vectorised), :mod:`~.profile`, :mod:`~.lag` and :mod:`~.sensor` (the wire's
  temperature, and when a lag can be fitted), :mod:`~.layout`, :mod:`~.centres` (the
  centre laws: linear, or following Clausius-Clapeyron) and :mod:`~.starts` (the unknowns,
  their starts and bounds), :mod:`~.jacobian` and
  :mod:`~.solver` (sparse Levenberg-Marquardt), :mod:`~.covariance`, :mod:`~.outliers`
  (outlier cycles, bounds) and :mod:`~.outcome` (what the fit found, the verdict, judged
  against noise floored at the file's written step, :mod:`~.resolution`);
- :mod:`~.centre_law`: the report's word on the centre law (the centres' standard errors,
  what was done with the shares);
- :mod:`~.halfway` and :mod:`~.summary`: half-strain temperatures and transformation strain
  of data and model per stress, and the text summary;
- :mod:`~.predict` and :mod:`~.predict_runner`: ``sma-fmu predict isobaric``, the plant
  runtime through a lab file's temperature history;
- :mod:`~.runner`: ``sma-fmu fit isobaric`` (the parameter file, report, per-cycle
  :mod:`~.tables` and :mod:`~.figures`); not imported here, so reading and fitting need no
  matplotlib;
- :mod:`~.synthetic`: seeded synthetic files for ``sma-fmu synth isobaric`` and the tests.
"""
from sma_fmu.identification.isobaric.files import IsobaricData, read_isobaric
from sma_fmu.identification.isobaric.fit import LAG_OPTIONS, RESIDUAL_OPTIONS, IsobaricFit, fit_isobaric
from sma_fmu.identification.isobaric.synthetic import IsobaricProgramme, isobaric_table, isobaric_text

__all__ = ["IsobaricData", "read_isobaric", "LAG_OPTIONS", "RESIDUAL_OPTIONS", "IsobaricFit",
           "fit_isobaric", "IsobaricProgramme", "isobaric_table", "isobaric_text"]
