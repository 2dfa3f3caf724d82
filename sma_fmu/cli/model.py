"""Model commands: lattice, wire, resistance, sense, constant-length (``name = value unit`` or JSON)."""
import math
import sys

from .arguments import Parser, direction, finite_number, require_inputs

__all__ = ["register"]


def _report(rows, as_json):
    """Print rows of (name, value, unit) as text lines or one JSON object."""
    if as_json:
        import json
        print(json.dumps({name: value for name, value, _ in rows}, allow_nan=False))
        return
    for name, value, unit in rows:
        text = f"{value:.6g}" if isinstance(value, float) else str(value)
        print(f"{name} = {text}{' ' + unit if unit else ''}")


def _lattice(args, parameter_set):
    lattice = parameter_set.params.lattice
    return [("N", lattice.N, ""), ("x_P", lattice.x_P, "m"), ("N_l", lattice.N_l, ""),
            ("N_S", lattice.N_S, "")] + _derived_notes(parameter_set)


def _derived_notes(parameter_set):
    """Rows saying which file values were derived from the geometry (none for a full file)."""
    return [(f"derived {name}", how, "") for name, how in parameter_set.derived.items()]


def _wire(args, parameter_set):
    from sma_fmu.runtime.parameters import PARAMETER_SPECS

    params = parameter_set.params
    rows = [("name", parameter_set.name, ""), ("file", str(parameter_set.path), "")]
    for spec in PARAMETER_SPECS:
        value = getattr(params, spec.name)
        if value is not None:
            unit = "" if spec.unit == "1" else spec.unit
            rows.append((f"{spec.section}.{spec.name}", value, unit))
    rows += _derived_notes(parameter_set)
    rows += [("K_th", params.K_th, "K/W"), ("tau_th", params.tau_th, "s"),
             ("alpha (phase-lag lead time)", params.phase_lag_alpha, "s"),
             ("surface pi d x0", math.pi * params.diameter * params.x0, "m2"),
             ("line density mass/x0", params.line_density, "kg/m"),
             ("R fully hot, no load", params.R_P, "ohm"), ("R fully cold", params.R_MF, "ohm"),
             ("note", f"T_room = {params.T_room:g} degC is the ambient of the paper's tests; "
                      f"set thermal.T_room to yours", "")]
    return rows


def _resistance(args, parameter_set):
    from sma_fmu.runtime.checks import direction_name
    from sma_fmu.runtime.constant_load import constant_load_fractions
    from sma_fmu.runtime.phases import length_of, resistance_of

    params = parameter_set.params
    fractions = constant_load_fractions(args.temperature, args.load, args.direction, params)
    return [("temperature", args.temperature, "degC"), ("load", args.load, "kg"),
            ("direction", direction_name(args.direction), ""),
            ("R", resistance_of(fractions, params), "ohm"),
            ("xi_P", fractions.xi_P, ""), ("xi_M", fractions.xi_M, ""),
            ("xi_F", fractions.xi_F, ""), ("x", length_of(fractions, params), "m")]


def _sense(args, parameter_set):
    from sma_fmu.runtime.checks import direction_name
    from sma_fmu.runtime.sensing import sense_temperature

    sensed = sense_temperature(args.resistance, args.load, args.direction, parameter_set.params)
    return [("resistance", args.resistance, "ohm"), ("load", args.load, "kg"),
            ("direction", direction_name(args.direction), ""),
            ("T", sensed.temperature, "degC"), ("saturated", sensed.saturated, "")]


def _constant_length(args, parameter_set):
    from sma_fmu.runtime.constant_length import load_temperature_slope

    slope = load_temperature_slope(args.xi_p, args.xi_m, args.xi_f, parameter_set.params)
    return [("xi_P", args.xi_p, ""), ("xi_M", args.xi_m, ""), ("xi_F", args.xi_f, ""),
            ("df_dT", slope, "kg/K")]


def _warn_load(args, params):
    """One ``sma-fmu: warning:`` line on stderr for a --load above the validity limit, as the
    FMUs warn (runtime/validity.py)."""
    from sma_fmu.runtime.validity import validity_warning

    load = getattr(args, "load", None)
    message = None if load is None else validity_warning(params, -math.inf, -math.inf, load, -math.inf)
    if message:
        print(f"sma-fmu: warning: --load: {message}", file=sys.stderr)


def _handler(compute):
    """Handler that loads the parameter file, computes rows and prints them."""
    def handler(args):
        require_inputs((args.model, "parameter file"))
        from sma_fmu.wire.parameter_file import load_parameter_set

        parameter_set = load_parameter_set(args.model)
        rows = compute(args, parameter_set)
        _warn_load(args, parameter_set.params)
        _report(rows, args.json)
        return 0
    return handler


def register(commands):
    """Add the model commands to the ``commands`` subparsers."""
    common = Parser(add_help=False)
    common.add_argument("--model", metavar="FILE",
                        help="parameter file (default: the shipped reference_wire.toml)")
    common.add_argument("--json", action="store_true", help="print one JSON object")

    lattice = commands.add_parser("lattice", parents=[common],
                                  help="lattice constants N, x_P, N_l, N_S")
    lattice.set_defaults(handler=_handler(_lattice))

    wire = commands.add_parser("wire", parents=[common],
                               help="the wire's parameters, what was derived from its geometry, "
                                    "and the constants that follow")
    wire.set_defaults(handler=_handler(_wire))

    resistance = commands.add_parser("resistance", parents=[common],
                                     help="resistance, fractions and length at T, load, direction")
    resistance.add_argument("--temperature", required=True, type=finite_number, metavar="C",
                            help="wire temperature [degC]")
    resistance.add_argument("--load", required=True, type=finite_number, metavar="KG",
                            help="hung mass [kg]")
    _add_direction(resistance)
    resistance.set_defaults(handler=_handler(_resistance))

    sense = commands.add_parser("sense", parents=[common],
                                help="temperature from resistance (inverse model)")
    sense.add_argument("--resistance", required=True, type=finite_number, metavar="OHM",
                       help="wire resistance [ohm]")
    sense.add_argument("--load", required=True, type=finite_number, metavar="KG", help="hung mass [kg]")
    _add_direction(sense)
    sense.set_defaults(handler=_handler(_sense))

    length = commands.add_parser("constant-length", parents=[common],
                                 help="(df/dT)_x of a wire held at constant length [kg/K]")
    length.add_argument("--xi-p", required=True, type=finite_number, help="P fraction [1]")
    length.add_argument("--xi-m", required=True, type=finite_number, help="M fraction [1]")
    length.add_argument("--xi-f", required=True, type=finite_number, help="F fraction [1]")
    length.set_defaults(handler=_handler(_constant_length))


def _add_direction(parser):
    parser.add_argument("--direction", required=True, type=direction,
                        metavar="heating|cooling", help="sign of dT/dt")
