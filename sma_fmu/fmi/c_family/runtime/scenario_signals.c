/* A scenario's signals as a co-simulation source; runtime/scenario_signals.py (see
 * scenario_signals.h). */
#include "fp_contract.h"
#include "scenario_signals.h"

#include <math.h>
#include <string.h>

#include "checks.h"
#include "json_text.h"
#include "state_entries.h"

#define SIGNALS_STATE_SIZE 1
#define TWO_TO_52 4503599627370496.0

/* _table: the JSON object in `text`, else Python's message naming the parameter. */
static int table_of(const char *name, const char *text, JsonValue *table, SmaMessage *message)
{
    char error[256], repr[400];
    if (text == NULL) {
        return sma_message_set(message, "%s must be a JSON object in a string, got None", name);
    }
    if (json_text_parse(text, table, error, sizeof error)) {
        json_text_repr(text, strlen(text), repr, sizeof repr);
        return sma_message_set(message, "%s is not valid JSON (%s): %s", name, error, repr);
    }
    if (table->kind != JSON_OBJECT) {
        json_value_free(table);
        json_text_repr(text, strlen(text), repr, sizeof repr);
        return sma_message_set(message, "%s must be a JSON object, got %s", name, repr);
    }
    return 0;
}

/* One parameter: build its signal; a message not starting with the name gets "name: ". */
static int signal_of(const char *name, const char *text, ReferenceSignal *reference,
                     LoadProfile *load, SmaMessage *message)
{
    SmaMessage inner;
    JsonValue table;
    int failed = table_of(name, text, &table, &inner);
    if (!failed) {
        failed = reference != NULL ? reference_from_table(&table, reference, &inner)
                                   : load_from_table(&table, load, &inner);
        json_value_free(&table);
    }
    if (!failed) {
        return 0;
    }
    if (strncmp(inner.text, name, strlen(name)) == 0) {
        return sma_message_set(message, "%s", inner.text);
    }
    return sma_message_set(message, "%s: %s", name, inner.text);
}

int signals_from_text(const char *reference_text, const char *load_text,
                      ReferenceSignal *reference, LoadProfile *load, SmaMessage *message)
{
    ReferenceSignal built;
    if (signal_of("reference", reference_text, &built, NULL, message)) {
        return 1;
    }
    if (signal_of("load_profile", load_text, NULL, load, message)) {
        reference_signal_free(&built);
        return 1;
    }
    *reference = built;
    return 0;
}

int grid_point(double time_s, double start_s, double step_s, double *grid)
{
    double steps = (time_s - start_s) / step_s, point;
    if (!(fabs(steps) < TWO_TO_52)) {   /* beyond the integers a double holds (or inf, nan) */
        return 0;
    }
    point = start_s + (nearbyint(steps) + 0.0) * step_s;   /* + 0.0: Python's int has no -0 */
    if (fabs(time_s - point) <= GRID_TOLERANCE * step_s) {
        *grid = point;
        return 1;
    }
    return 0;
}

double grid_time(double time_s, double start_s, double step_s)
{
    double grid;
    return grid_point(time_s, start_s, step_s, &grid) ? grid : time_s;
}

static int sample(const SignalSource *source, double time_s, SignalOutputs *outputs,
                  SmaMessage *message)
{
    if (reference_signal_value(&source->reference, time_s, &outputs->R_ref, message)) {
        return 1;
    }
    outputs->load = load_profile_value(&source->load, time_s, LOAD_TOLERANCE_S);
    return 0;
}

int signal_source_init(SignalSource *source, ReferenceSignal *reference, LoadProfile *load,
                       double start_time, SmaMessage *message)
{
    source->reference = *reference;
    source->load = *load;
    if (require_finite("start time", start_time, message)) {
        signal_source_free(source);
        return 1;
    }
    source->start_time = source->time = start_time;
    source->has_grid_step = 0;
    source->grid_step = 0.0;
    if (sample(source, source->time, &source->outputs, message)) {
        signal_source_free(source);
        return 1;
    }
    return 0;
}

int signal_source_step(SignalSource *source, double current_time, double step_size,
                       SignalOutputs *outputs, SmaMessage *message)
{
    double end;
    SignalOutputs sampled;
    if (fast_finite("current time", current_time, message)
        || fast_positive("step_size", step_size, message)) {
        return 1;
    }
    end = current_time + step_size;
    if (!source->has_grid_step) {
        source->has_grid_step = 1;
        source->grid_step = step_size;
    }
    if (fast_finite("current time + step_size", end, message)) {
        return 1;
    }
    end = grid_time(end, source->start_time, source->grid_step);
    if (sample(source, end, &sampled, message)) {
        return 1;
    }
    source->outputs = sampled;
    source->time = end;
    *outputs = sampled;
    return 0;
}

void signal_source_free(SignalSource *source)
{
    reference_signal_free(&source->reference);
    load_profile_free(&source->load);
}

size_t signal_source_state_size(const SignalSource *source)
{
    (void)source;
    return SIGNALS_STATE_SIZE;
}

void signal_source_state_write(const SignalSource *source, double *out)
{
    out[0] = source->time;
}

int signal_source_state_read(SignalSource *source, const double *in, size_t count,
                             SmaMessage *message)
{
    SignalOutputs outputs;
    if (read_entries(count, SIGNALS_STATE_SIZE, "signals state", message)
        || read_number(in[0], "time", 0.0, HUGE_VAL, "s", message)
        || sample(source, in[0], &outputs, message)) {
        return 1;
    }
    source->time = in[0];
    source->outputs = outputs;
    return 0;
}
