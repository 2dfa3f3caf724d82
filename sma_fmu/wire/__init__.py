"""A wire's parameter set as data: parameter files (parameter_file: read, check, write the
models/*.toml format) and the parameters derived from a wire's geometry (geometry)."""
