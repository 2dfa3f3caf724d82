"""The model's warnings of one run, each distinct text once: what ``sma-fmu run`` reports.

The runtime's steppers set a warning when a run leaves the wire's validity range or the
range of the data it was fitted to (:mod:`sma_fmu.runtime.validity`); the FMUs of both
families log the same text as a Warning, after the model, the instance and the FMI function
that raised it ("SmaActuator 'plant': fmi2DoStep: "). Each path gathers them here: the library
path from the steppers, the fmpy master from its instances' logs, the C master from its
host's log frames. The texts are the runtime's (the function's name taken off), kept in
the order of the loop's components (:data:`COMPONENT_ORDER`), each component's in the order
logged, so one run gives the same list on every path.

A text may carry a value (the temperature of one excursion above ``T_max``), so a long run
could give many: the first :data:`WARNINGS_KEPT` distinct texts of a component are kept, the
messages after them counted in one last line.
"""
import re

__all__ = ["WARNINGS_KEPT", "COMPONENT_ORDER", "WarningTexts", "model_text", "ordered"]

WARNINGS_KEPT = 20   # distinct texts listed per component and run; the rest are counted
COMPONENT_ORDER = ("plant", "compensator")   # then any other component, by name
_WHERE = re.compile(r"(?:\w+ '[^']*': )?fmi[23][A-Za-z]+: ")   # "MODEL 'INSTANCE': fmi2Call: "


def model_text(message):
    """The runtime's text of an FMU's warning ``message`` (the model, instance and FMI
    function before it taken off; a message without them as it is)."""
    match = _WHERE.match(message)
    return message[match.end():] if match else message


class WarningTexts:
    """The distinct warning texts of one component in one run, in the order first given."""

    def __init__(self):
        self._texts = {}
        self.more = 0    # messages not listed: new texts after WARNINGS_KEPT were kept

    def add(self, text):
        """Keep ``text`` [str] unless it was given before."""
        if text in self._texts:
            return
        if len(self._texts) < WARNINGS_KEPT:
            self._texts[text] = None
        else:
            self.more += 1   # (not remembered: memory stays bounded, a repeat counts again)

    def texts(self):
        """The kept texts, and a line counting the others if there were any."""
        texts = list(self._texts)
        if self.more:
            texts.append(f"and {self.more} more warning messages (not listed)")
        return texts


def ordered(by_component):
    """The texts of ``by_component`` ({component name: :class:`WarningTexts`}) as one list,
    the components in :data:`COMPONENT_ORDER`, then the others by name; each text once."""
    names = sorted(by_component, key=lambda name: (
        COMPONENT_ORDER.index(name) if name in COMPONENT_ORDER else len(COMPONENT_ORDER), name))
    return list(dict.fromkeys(text for name in names for text in by_component[name].texts()))
