"""Co-simulation: scenario files, the closed loop, the fmpy master, metrics, results and figures."""
