"""Parameter identification from measurements: CSV readers, least squares, fits, synthetic data, figures."""
