"""The closed loop of one scenario as a single FMI 2.0 co-simulation FMU (an FMU container).

Built with fmu-manipulation-toolbox's container builder in sequential mode: inside each
doStep the embedded FMUs step one after another in :data:`~sma_fmu.fmi.loop.wiring.STEP_ORDER`
(compensator, PI, plant, signals), each with the outputs just computed by the ones before
it (Gauss-Seidel), so the container computes exactly what the library loop computes.
Every embedded FMU is named as in the SSP, packed with the scenario's values as its
defaults (:mod:`.packed`), and its parameters are also set to them as start values. The
container has no inputs; its outputs are the loop system's (:data:`~sma_fmu.fmi.loop.wiring.OUTPUTS`),
with the units of the embedded FMUs (added to the builder's modelDescription.xml, which has none).

The container passes an embedded FMU's warnings from fmi2DoStep on, but takes one from
fmi2ExitInitializationMode for a failure: its own fmi2ExitInitializationMode then returns
fmi2Error (fmpy stops, libcosim ends the process). The plant warns there when it starts
outside its wire's data range (``validity.T_data_min`` ..., as the Flexinol fit's stroke
scenarios start, at T_room 10 degC against data from 29.8 degC), so such a scenario is
refused before anything is built (:func:`container_refusal`).
"""
import io
import tempfile
import xml.etree.ElementTree as ET
import zipfile
from pathlib import Path

from sma_fmu.cosim.scenario import load_scenario
from sma_fmu.fmi.python_family.slave_support.model_description import set_units
from sma_fmu.files.output_folder import OutputError, write_file
from sma_fmu.runtime.plant import PlantStepper
from sma_fmu.systems.closed_loop import closed_loop, identifier
from sma_fmu.systems.packed import packed_fmu
from sma_fmu.systems.toolbox_log import toolbox_messages

__all__ = ["build_container", "export_container", "container_refusal"]


def _text(value):
    """A start value as the builder wants it (a string without spaces)."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return repr(value)
    text = str(value)
    if any(character.isspace() for character in text):
        raise ValueError(f"start value {text!r} contains white space, which an FMU container "
                         "cannot carry")
    return text


# what the builder says about this loop by design: the PI and the plant form a loop (the
# PI is initialized before the plant's R reaches it; its first step then reads R_0), and
# the step order puts the signals after the blocks that read them (see STEP_ORDER)
_EXPECTED = ("Loop of links through the embedded FMU 'pi'",
             "Sequential mode: the order of the configuration does not match")
# ... and without a compensator the PI's P_ff keeps its start value, 0 W
_EXPECTED_WITHOUT_COMPENSATOR = _EXPECTED + ("Input 'Port pi/P_ff' is not connected",)
# ... and a driver with a current or voltage limit reads the plant's R (the same loop as the
# PI's); one without a limit leaves that input unconnected (it is not read)
_EXPECTED_LIMITED = ("Loop of links through the embedded FMU 'driver'",)
_EXPECTED_UNLIMITED_DRIVER = ("Input 'Port driver/R' is not connected",)


def container_refusal(scenario):
    """Why ``scenario`` cannot run as a container (its plant warns at initialization,
    which the container reports as an error: see the module docstring), or None."""
    warning = PlantStepper(scenario.params, scenario.T_start, scenario.hysteresis_mode,
                           scenario.load.value(0.0)).warning
    if warning is None:
        return None
    return (f"the plant warns at its start ({warning}), and an FMU container takes a warning "
            f"at initialization for an error (its fmi2ExitInitializationMode fails); start "
            f"the wire inside its data range ([plant] T_start_degC), or run the loop as an "
            f"SSP (--path ssp, export ssp)")


def _configure(container, system):
    for component in system.in_step_order():  # the sequential mode steps in this order
        container.get_fmu(Path(component.fmu).name, name=component.name)
    for connection in system.connections:
        container.add_link(connection.source, connection.output, connection.target, connection.input)
    for exposed, (component, variable) in system.outputs.items():
        container.add_output(component, variable, exposed)
    for component in system.components:
        for name, value in component.parameters.items():
            container.add_start_value(component.name, name, _text(value))
    container.drop_port("plant", "heating")
    container.drop_port("pi", "R_measured")   # the sensor's reading: the PI's own business
    container.add_implicit_rule(auto_input=False, auto_output=False, auto_link=False)


def _units(system):
    """{container output: unit} from the embedded FMUs' model variables."""
    units = {}
    for exposed, (name, variable) in system.outputs.items():
        unit = system.component(name).variables[variable].unit
        if unit:
            units[exposed] = unit
    return units


def _with_units(archive, units):
    """The container FMU ``archive`` (bytes) with UnitDefinitions and a unit on each output."""
    buffer = io.BytesIO()
    with zipfile.ZipFile(io.BytesIO(archive)) as source, \
            zipfile.ZipFile(buffer, "w", zipfile.ZIP_DEFLATED) as target:
        for item in source.infolist():
            data = source.read(item.filename)
            if item.filename == "modelDescription.xml":
                root = set_units(ET.fromstring(data), units)
                data = ET.tostring(root, encoding="UTF-8", xml_declaration=True)
            target.writestr(item, data)
    return buffer.getvalue()


def build_container(system, out, step_size=None, argument="--out"):
    """Write the container FMU of ``system`` (a :class:`~sma_fmu.fmi.loop.system.LoopSystem`) to ``out``.

    ``step_size`` [s]: the internal step (default: the scenario's). Returns ``out``.
    Anything the builder reports beyond what this loop makes it say (``_EXPECTED``) is an
    error.
    """
    from fmu_manipulation_toolbox.container import FMUContainer
    from fmu_manipulation_toolbox.container.errors import FMUContainerError

    scenario = system.scenario
    refusal = container_refusal(scenario)
    if refusal:
        raise ValueError(f"{scenario.path}: {refusal}")
    step_size = scenario.step_s if step_size is None else step_size
    expected = _EXPECTED if scenario.controller.feedforward else _EXPECTED_WITHOUT_COMPENSATOR
    if scenario.drive.driver:
        expected += _EXPECTED_LIMITED if scenario.drive.limited else _EXPECTED_UNLIMITED_DRIVER
    try:
        with toolbox_messages() as messages, \
                tempfile.TemporaryDirectory(prefix="sma_fmu_container_") as folder:
            for component in system.components:
                (Path(folder) / Path(component.fmu).name).write_bytes(packed_fmu(component, scenario))
            container = FMUContainer(identifier(scenario.name), folder, fmi_version=2)
            container.start_time, container.stop_time = 0.0, scenario.stop_time_s
            _configure(container, system)
            built = Path(folder) / "container.fmu"
            container.make_fmu(built.name, step_size=step_size, sequential=True)
            unexpected = [m for m in messages if not m.startswith(expected)]
            if unexpected or not built.is_file():
                raise ValueError(f"{out}: the container builder reports: "
                                 f"{'; '.join(unexpected) or 'no file written'}")
            write_file(out, _with_units(built.read_bytes(), _units(system)), argument)
    except FMUContainerError as error:
        raise ValueError(f"{out}: cannot build the container: {error}") from None
    return Path(out)


def export_container(scenario_path, out, fmu_dir):
    """Write the container FMU of one scenario file to ``out`` (a .fmu file); returns ``out``."""
    if Path(out).suffix.lower() != ".fmu":
        raise OutputError(f"--out {out}: a container is one FMU file; name it NAME.fmu")
    return build_container(closed_loop(load_scenario(scenario_path), fmu_dir), out)
