/* SmaScenarioSignals: a scenario's reference R_ref(t) and load f(t), native.
 *
 * A thin adapter over runtime/scenario_signals (SignalSource), as
 * the slave beside it (sma_scenario_signals.py) is. Parameters: reference and load_profile, String
 * parameters holding a scenario's [reference] and [load] tables as JSON objects (read with
 * the runtime's JSON reader); their defaults are the build's default scenario, or in an
 * FMU packed by `sma-fmu export` the exported scenario's (resources/start_values.json).
 * A source: after initialization the outputs are the signals at the start time; after
 * doStep(t, h) at t + h, on the step's grid. Invalid tables refuse
 * ExitInitializationMode naming the parameter and the key. In FMI 3.0 event mode its events
 * are the load's switching times and the reference's step. */
#include "fp_contract.h"
#include "scenario_signals.h"
#include "SmaScenarioSignals_variables.h"

static int start(void *stepper, SmaValue *values, SmaRun *run, SmaMessage *message)
{
    SignalSource *source = (SignalSource *)stepper;
    ReferenceSignal reference;
    LoadProfile load;
    if (signals_from_text(values[VAR_reference].text, values[VAR_load_profile].text, &reference,
                          &load, message) ||
        signal_source_init(source, &reference, &load, run->start_time, message))
        return 1;
    values[VAR_R_ref].real = source->outputs.R_ref;
    values[VAR_load].real = source->outputs.load;
    return 0;
}

static int step(void *stepper, SmaValue *values, SmaRun *run, double time, double step_size,
                SmaMessage *message)
{
    SignalOutputs outputs;
    SignalSource *source = (SignalSource *)stepper;
    /* the grid's h0 is the run's first step, which a saved state keeps (SmaRun.first_step): a
     * restored source would otherwise take the next step's size, which a host that steps
     * from t to t_next passes a rounding error off h0, and sample off the saved run's grid */
    if (!(run->first_step > 0.0)) run->first_step = step_size;
    source->has_grid_step = 1;
    source->grid_step = run->first_step;
    if (signal_source_step(source, time, step_size, &outputs, message))
        return 1;
    values[VAR_R_ref].real = outputs.R_ref;
    values[VAR_load].real = outputs.load;
    return 0;
}

static void release(void *stepper) { signal_source_free((SignalSource *)stepper); }

static size_t state_size(const void *stepper)
{
    return signal_source_state_size((const SignalSource *)stepper);
}

static void state_write(const void *stepper, double *out)
{
    signal_source_state_write((const SignalSource *)stepper, out);
}

static int state_read(void *stepper, const double *in, size_t count, SmaMessage *message)
{
    return signal_source_state_read((SignalSource *)stepper, in, count, message);
}

/* The next discontinuity after `time` [s]: a load switching time or the reference's step
 * (ramps, waves and tables are continuous); a time within LOAD_TOLERANCE_S counts as now. */
static double next_event(const void *stepper, const SmaValue *values, double time)
{
    const SignalSource *source = (const SignalSource *)stepper;
    double next = time - 1.0;
    size_t i;
    (void)values;
    for (i = 0; i < source->load.count; ++i)
        if (source->load.times[i] > time + LOAD_TOLERANCE_S) {
            next = source->load.times[i];
            break;
        }
    if (source->reference.kind == REFERENCE_STEP &&
        source->reference.time_s > time + LOAD_TOLERANCE_S &&
        (next < time || source->reference.time_s < next))
        next = source->reference.time_s;
    return next;
}

const SmaModel SMA_MODEL = {
    MODEL_NAME, MODEL_GUID, "sma-fmu signals state", LOG_CATEGORIES, VARIABLES, VAR_COUNT,
    0, sizeof(SignalSource), start, step, release, NULL, state_size, state_write, state_read,
    next_event,
    0, 0, NULL, NULL, NULL};
