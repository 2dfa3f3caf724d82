"""What the user sees at the console besides results: progress bars (one library, tqdm;
shown on a terminal only), Ctrl-C (one line, exit 130, nothing half-written) and the extra
to install when a command needs an optional dependency.

- :mod:`.progress`: :func:`~.progress.bar`, :func:`~.progress.configure` (``--quiet``);
- :mod:`.interrupts`: the SIGINT handler of the command line and the sections a Ctrl-C
  waits for (:func:`~.interrupts.deferred`);
- :mod:`.extras`: the optional dependencies, by extra, and :func:`~.extras.require`.
"""
__all__ = []
