"""Small functions compiled once from variable names: the per-step code of the slaves.

A slave's variables are attributes. Code that reads or writes a fixed list of them at every
step is fastest as plain attribute accesses (``slave.R, slave.T = values``), so it is
generated once from the names instead of looping over ``getattr``/``setattr`` (about five
times slower per step). Names that are not identifiers get the loop. Each source text is
compiled once per process (instances of a slave share the code; compiling per instance
costs memory the allocator keeps).
"""
import keyword

__all__ = ["identifiers", "compile_function", "attribute_reader", "attribute_writer", "stepper_call"]


def identifiers(names):
    """True if every name can be written as ``obj.<name>`` in generated code."""
    return all(name.isidentifier() and not keyword.iskeyword(name) for name in names)


_DEFINED = {}  # (source, name, label) -> function


def compile_function(source, name, scope=None, label="<sma-fmu compiled>"):
    """The function ``name`` defined by ``source`` (generated from checked identifiers) in a
    namespace holding ``scope``: defined once per source text, so equal sources must come
    with equal scopes (constants)."""
    key = (source, name, label)
    function = _DEFINED.get(key)
    if function is None:
        namespace = dict(scope or {})
        exec(compile(source, label, "exec"), namespace)  # noqa: S102 - names checked by the callers
        function = _DEFINED.setdefault(key, namespace[name])
    return function


def attribute_reader(names):
    """A function obj -> tuple of the attributes ``names`` of obj."""
    names = tuple(names)
    if identifiers(names) and "obj" not in names:
        values = "".join(f"obj.{name}, " for name in names)
        return compile_function(f"def read(obj):\n    return ({values})\n", "read")
    return lambda obj: tuple(getattr(obj, name) for name in names)


def attribute_writer(names):
    """A method (self, values) that sets the attributes ``names`` of self to ``values``
    (a sequence of that length), in order."""
    names = tuple(names)
    if identifiers(names) and names:
        targets = ", ".join(f"self.{name}" for name in names)
        return compile_function(f"def write(self, values):\n    {targets}, = values\n", "write")

    def write(self, values):
        values = tuple(values)
        if len(values) != len(names):
            raise ValueError(f"{len(values)} values for {len(names)} variables")
        for name, value in zip(names, values):
            setattr(self, name, value)
    return write


def stepper_call(method, names):
    """A method (self, current_time, step_size) returning
    ``self.stepper.<method>(self.<name>..., step_size)``."""
    names = tuple(names)
    if not method.isidentifier():
        raise ValueError(f"stepper method {method!r} is not an identifier")
    if identifiers(names):
        arguments = "".join(f"self.{name}, " for name in names)
        return compile_function(
            f"def advance(self, current_time, step_size):\n"
            f"    return self.stepper.{method}({arguments}step_size)\n", "advance")

    def advance(self, current_time, step_size):
        return getattr(self.stepper, method)(*(getattr(self, name) for name in names), step_size)
    return advance
