"""The top-level packages a Python source imports (absolute imports only): one AST walk
for the tests that pin what the runtime, the FMU resources and the examples may import."""
import ast

__all__ = ["imported_roots"]


def imported_roots(source):
    """Set of the first components of every absolute import in ``source`` (text)."""
    roots = set()
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Import):
            roots |= {alias.name.split(".")[0] for alias in node.names}
        elif isinstance(node, ast.ImportFrom) and node.level == 0:
            roots.add(node.module.split(".")[0])
    return roots
