"""`sma-fmu bench`: how fast the FMUs, the co-simulation, the batch engine and the fits run
(benchmark), and the FMUs in C hosts (c_hosts)."""
