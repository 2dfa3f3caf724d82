"""Parameter identification from measurements: CSV readers, least squares, fits, synthetic data, figures.

- :mod:`~.constant_load`, :mod:`~.constant_temperature`: the paper's two resistance
  experiments (``sma-fmu fit constant-load|constant-temperature``), on :mod:`~.measurements`,
  :mod:`~.least_squares`, :mod:`~.runner`, :mod:`~.synthetic` and :mod:`~.figures`;
- :mod:`~.isobaric`: the subpackage of the isobaric fit, a lab's thermal-cycling files to a
  parameter file (``sma-fmu fit isobaric``, ``sma-fmu synth isobaric``);
- :mod:`~.transformation_temperatures`: the tangent construction shared by both.
"""
