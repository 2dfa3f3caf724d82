"""Files in and out: the shipped data (package_data), TOML reading with clear errors
(toml_files), JSON output (json_output) and output folders that are never left half-written
(output_folder)."""
