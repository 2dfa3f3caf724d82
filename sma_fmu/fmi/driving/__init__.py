"""Running FMUs from Python: one instance through fmpy with variables by name
(:mod:`.instance`), each FMU file unpacked once per process (:mod:`.unpacked`), and the
model description read with one named error (:mod:`.description`)."""
