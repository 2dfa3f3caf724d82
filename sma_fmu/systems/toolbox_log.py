"""fmu-manipulation-toolbox reports problems in its log rather than raising: collect them."""
import contextlib
import logging

__all__ = ["toolbox_messages"]

_LOGGER = "fmu_manipulation_toolbox"


class _Collector(logging.Handler):
    def __init__(self, level, messages):
        super().__init__(level=level)
        self.messages = messages

    def emit(self, record):
        self.messages.append(record.getMessage())


@contextlib.contextmanager
def toolbox_messages(level=logging.WARNING):
    """Yield a list that collects the toolbox's messages at ``level`` and above.

    Meanwhile they reach no other handler (no stray lines on the console).
    """
    messages, logger = [], logging.getLogger(_LOGGER)
    collector = _Collector(level, messages)
    logger.addHandler(collector)
    propagate, logger.propagate = logger.propagate, False
    try:
        yield messages
    finally:
        logger.removeHandler(collector)
        logger.propagate = propagate
