/* Getting and setting variables by value reference (for both FMI fronts), with the
 * pythonfmu FMUs' rules and messages.
 *
 * Which variable may be set in which state is lifecycle.py's table; the refusals are
 * SlaveInterface.setting_refusal / describe_reference's texts, followed by "; nothing was
 * set (value <repr>)" (guards.py: all or nothing). In Initialization Mode a get first
 * computes the outputs from what was set (guard._refresh_initial_outputs). */
#include "fp_contract.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "layer.h"

/* unknown value references a refused get describes; the rest are counted (refusal_text.py) */
#define REFERENCES_SHOWN 5

static const char *const KIND_NAMES[] = {"Real", "Integer", "Boolean", "String"};
static const char *const FMI3_KIND_NAMES[] = {"Float64", "Int32", "Boolean", "String"};
static const char *const CAUSALITY_NAMES[] = {"parameter", "input", "output", "local"};

const SmaVariable *layer_variable(const SmaModel *model, unsigned int vr, size_t *index)
{
    size_t i;
    if (vr < model->count && model->variables[vr].vr == vr) {  /* pythonfmu numbers 0, 1, ... */
        if (index) *index = vr;
        return &model->variables[vr];
    }
    for (i = 0; i < model->count; ++i) {
        if (model->variables[i].vr == vr) {
            if (index) *index = i;
            return &model->variables[i];
        }
    }
    return NULL;
}

int layer_values_init(Instance *in)
{
    const SmaModel *model = in->model;
    size_t i;
    if (!in->real_outputs) {  /* once per instance: the step checks only these */
        in->real_outputs = (size_t *)malloc((model->count ? model->count : 1) * sizeof(size_t));
        if (!in->real_outputs) return 0;
        in->real_output_count = 0;
        for (i = 0; i < model->count; ++i)
            if (model->variables[i].kind == SMA_REAL && model->variables[i].causality == SMA_OUTPUT)
                in->real_outputs[in->real_output_count++] = i;
    }
    in->values = (SmaValue *)calloc(model->count ? model->count : 1, sizeof *in->values);
    if (!in->values) return 0;
    for (i = 0; i < model->count; ++i) {
        const SmaVariable *v = &model->variables[i];
        if (v->kind == SMA_REAL) in->values[i].real = v->start;
        else if (v->kind == SMA_STRING) {
            const char *text = v->start_text ? v->start_text : "";
            in->values[i].text = (char *)malloc(strlen(text) + 1);
            if (!in->values[i].text) return 0;
            strcpy(in->values[i].text, text);
        } else in->values[i].integer = (int)v->start;
    }
    return 1;
}

void layer_values_free(const SmaModel *model, SmaValue *values)
{
    size_t i;
    if (!values) return;
    for (i = 0; i < model->count; ++i)
        if (model->variables[i].kind == SMA_STRING) free(values[i].text);
    free(values);
}

SmaValue *layer_values_copy(const SmaModel *model, const SmaValue *values)
{
    size_t i;
    SmaValue *copy = (SmaValue *)calloc(model->count ? model->count : 1, sizeof *copy);
    if (!copy) return NULL;
    for (i = 0; i < model->count; ++i) {
        copy[i] = values[i];
        if (model->variables[i].kind == SMA_STRING) {
            copy[i].text = (char *)malloc(strlen(values[i].text) + 1);
            if (!copy[i].text) {
                while (i-- > 0)
                    if (model->variables[i].kind == SMA_STRING) free(copy[i].text);
                free(copy);
                return NULL;
            }
            strcpy(copy[i].text, values[i].text);
        }
    }
    return copy;
}

int layer_outputs_finite(const Instance *in, const SmaValue *values)
{
    const size_t *index = in->real_outputs, *end = index + in->real_output_count;
    for (; index < end; ++index)
        if (!isfinite(values[*index].real)) return 0;
    return 1;
}

void layer_drop_stepper(Instance *in)
{
    if (!in->stepper) return;
    if (in->model->free) in->model->free(in->stepper);
    free(in->stepper);
    in->stepper = NULL;
}

int layer_run_initialization(Instance *in, char *why, size_t size)
{
    SmaMessage message;
    void *stepper;
    layer_drop_stepper(in);  /* a failed start leaves none (StepperSlave) */
    stepper = calloc(1, in->model->stepper_size ? in->model->stepper_size : 1);
    if (!stepper) {
        snprintf(why, size, "MemoryError: out of memory");
        return 1;
    }
    message.text[0] = '\0';
    if (in->model->start(stepper, in->values, &in->run, &message)) {
        free(stepper);
        snprintf(why, size, "%.*s", (int)(size > 1 ? size - 1 : 0), message.text);
        return 1;
    }
    in->stepper = stepper;
    if (!layer_outputs_finite(in, in->values)) {
        snprintf(why, size, "the outputs are not finite");
        return 1;
    }
    return 0;
}

int layer_refresh_outputs(Instance *in, const char *function)
{
    char why[sizeof in->initial_error + 40];
    if (!in->outputs_current) {
        in->outputs_current = 1;
        in->initial_error[0] = '\0';
        if (layer_run_initialization(in, in->initial_error, sizeof in->initial_error) &&
            !in->initial_error[0])
            snprintf(in->initial_error, sizeof in->initial_error, "ValueError");
    }
    if (in->initial_error[0]) {
        snprintf(why, sizeof why, "the outputs are undefined: %s", in->initial_error);
        layer_refuse(in, SMA_ERROR, function, why);
        return 0;
    }
    return 1;
}

/* describe_reference: a value reference that is not a `kind` variable. */
static void describe_reference(const Instance *in, SmaKind kind, unsigned int vr, char *text,
                               size_t size)
{
    const SmaVariable *v = layer_variable(in->model, vr, NULL);
    if (!v)
        snprintf(text, size, "value reference %u is not a variable of %s", vr, in->model->name);
    else {
        const char *const *names = in->prefix[3] == '3' ? FMI3_KIND_NAMES : KIND_NAMES;
        snprintf(text, size, "value reference %u is %s variable %s, not a %s", vr,
                 names[v->kind], v->name, names[kind]);
    }
}

/* lifecycle.setting_refusal: NULL if a variable of this causality and variability may be
 * set in `state`, else why not. */
static const char *setting_refusal(const SmaVariable *v, LayerState state, const char *prefix,
                                   char *text, size_t size)
{
    int settable;
    if (v->causality == SMA_INPUT)
        settable = state == STATE_INSTANTIATED || state == STATE_INITIALIZATION ||
                   state == STATE_STEP_COMPLETE;
    else if (v->causality == SMA_PARAMETER && v->variability == SMA_FIXED)
        settable = state == STATE_INSTANTIATED || state == STATE_INITIALIZATION;
    else if (v->causality == SMA_PARAMETER && v->variability == SMA_TUNABLE)
        settable = state == STATE_INSTANTIATED || state == STATE_INITIALIZATION ||
                   state == STATE_STEP_COMPLETE;
    else {
        const char *causality = CAUSALITY_NAMES[v->causality];
        snprintf(text, size, "it is %s %s; only inputs and parameters can be set",
                 strchr("aeiou", causality[0]) ? "an" : "a", causality);
        return text;
    }
    if (settable) return NULL;
    if (v->causality == SMA_PARAMETER && v->variability == SMA_FIXED) {
        snprintf(text, size, "it is a fixed parameter; fixed parameters can be set only before "
                 "%sExitInitializationMode", prefix);
        return text;
    }
    snprintf(text, size, "the instance is in state '%s'", STATE_NAMES[state]);
    return text;
}

/* repr of the i-th value of a `kind` array, as the guard's message shows it. */
static void value_repr(SmaKind kind, const void *value, size_t i, char *text, size_t size)
{
    if (kind == SMA_REAL) layer_repr(((const double *)value)[i], text);
    else if (kind == SMA_INTEGER) snprintf(text, size, "%d", ((const int *)value)[i]);
    else if (kind == SMA_BOOLEAN) snprintf(text, size, "%s", ((const int *)value)[i] ? "True" : "False");
    else snprintf(text, size, "'%.200s'", ((const char *const *)value)[i]);
}

/* The common set, inputs by their own index (pythonfmu's numbering) in a state that allows
 * setting them, done without building any text; 0: not that case (nothing set), layer_set's
 * full path decides. */
static int quick_set(Instance *in, SmaKind kind, const unsigned int vr[], size_t nvr,
                     const void *value)
{
    const SmaModel *model = in->model;
    size_t i;
    if (kind == SMA_STRING || in->state > STATE_STEP_COMPLETE) return 0;
    for (i = 0; i < nvr; ++i) {
        unsigned int r = vr[i];
        if (!(r < model->count && model->variables[r].vr == r && model->variables[r].kind == kind &&
              model->variables[r].causality == SMA_INPUT))
            return 0;
    }
    for (i = 0; i < nvr; ++i) {
        if (kind == SMA_REAL) in->values[vr[i]].real = ((const double *)value)[i];
        else if (kind == SMA_INTEGER) in->values[vr[i]].integer = ((const int *)value)[i];
        else in->values[vr[i]].integer = ((const int *)value)[i] ? 1 : 0;
    }
    if (in->state == STATE_INITIALIZATION) in->outputs_current = 0;
    return 1;
}

SmaStatus layer_set(Instance *in, const char *function, SmaKind kind,
                     const unsigned int vr[], size_t nvr, const void *value)
{
    size_t i, index = 0;
    char why[400], shown[220], text[700];
    if (quick_set(in, kind, vr, nvr, value)) return SMA_OK;
    if (in->state != STATE_INSTANTIATED && in->state != STATE_INITIALIZATION &&
        in->state != STATE_STEP_COMPLETE) {
        snprintf(text, sizeof text, "illegal call in state '%s'", STATE_NAMES[in->state]);
        return layer_refuse(in, SMA_ERROR, function, text);
    }
    for (i = 0; i < nvr; ++i) {  /* all checked before anything is set */
        const SmaVariable *v = layer_variable(in->model, vr[i], NULL);
        const char *problem = NULL;
        if (!v || v->kind != kind) {
            describe_reference(in, kind, vr[i], why, sizeof why);
            problem = why;
        } else {
            char refusal[200];
            const char *reason = setting_refusal(v, in->state, in->prefix, refusal, sizeof refusal);
            if (reason) {
                snprintf(why, sizeof why, "%s (value reference %u) cannot be set: %s", v->name,
                         vr[i], reason);
                problem = why;
            }
        }
        if (problem) {
            value_repr(kind, value, i, shown, sizeof shown);
            snprintf(text, sizeof text, "%s; nothing was set (value %s)", problem, shown);
            return layer_refuse(in, SMA_ERROR, function, text);
        }
    }
    for (i = 0; i < nvr; ++i) {
        layer_variable(in->model, vr[i], &index);
        if (kind == SMA_REAL) in->values[index].real = ((const double *)value)[i];
        else if (kind == SMA_INTEGER) in->values[index].integer = ((const int *)value)[i];
        else if (kind == SMA_BOOLEAN) in->values[index].integer = ((const int *)value)[i] ? 1 : 0;
        else {
            const char *source = ((const char *const *)value)[i];
            char *copy = (char *)malloc(strlen(source) + 1);
            if (!copy) return layer_refuse(in, SMA_ERROR, function, "out of memory");
            strcpy(copy, source);
            free(in->values[index].text);
            in->values[index].text = copy;
        }
    }
    if (in->state == STATE_INITIALIZATION) in->outputs_current = 0;
    return SMA_OK;
}

static void put_missing(SmaKind kind, void *value, size_t i)
{
    if (kind == SMA_REAL) ((double *)value)[i] = 0.0;
    else if (kind == SMA_STRING) ((const char **)value)[i] = "";
    else ((int *)value)[i] = 0;
}

/* The common get after initialization, every reference its own index (pythonfmu's
 * numbering) and of `kind`; 0: not that case, layer_get's full path writes every value. */
static int quick_get(const Instance *in, SmaKind kind, const unsigned int vr[], size_t nvr,
                     void *value)
{
    const SmaModel *model = in->model;
    size_t i;
    if (in->state < STATE_STEP_COMPLETE) return 0;
    for (i = 0; i < nvr; ++i) {
        unsigned int r = vr[i];
        if (!(r < model->count && model->variables[r].vr == r && model->variables[r].kind == kind))
            return 0;
        if (kind == SMA_REAL) ((double *)value)[i] = in->values[r].real;
        else if (kind == SMA_STRING) ((const char **)value)[i] = in->values[r].text;
        else ((int *)value)[i] = in->values[r].integer;
    }
    return 1;
}

SmaStatus layer_get(Instance *in, const char *function, SmaKind kind,
                     const unsigned int vr[], size_t nvr, void *value)
{
    size_t i, index, used = 0, unknown = 0;
    char text[1500];
    if (quick_get(in, kind, vr, nvr, value)) return SMA_OK;
    if (in->state == STATE_INSTANTIATED ||
        (in->state == STATE_INITIALIZATION && !layer_refresh_outputs(in, function))) {
        for (i = 0; i < nvr; ++i) put_missing(kind, value, i);
        if (in->state == STATE_INSTANTIATED) {
            snprintf(text, sizeof text, "illegal call in state '%s'", STATE_NAMES[in->state]);
            return layer_refuse(in, SMA_ERROR, function, text);
        }
        return SMA_ERROR;
    }
    text[0] = '\0';
    for (i = 0; i < nvr; ++i) {
        const SmaVariable *v = layer_variable(in->model, vr[i], &index);
        if (!v || v->kind != kind) {
            char why[300];
            put_missing(kind, value, i);
            if (++unknown > REFERENCES_SHOWN) continue;  /* counted after the loop */
            describe_reference(in, kind, vr[i], why, sizeof why);
            if (used < sizeof text)
                used += (size_t)snprintf(text + used, sizeof text - used, "%s%s",
                                         used ? ", " : "", why);
        } else if (kind == SMA_REAL) ((double *)value)[i] = in->values[index].real;
        else if (kind == SMA_STRING) ((const char **)value)[i] = in->values[index].text;
        else ((int *)value)[i] = in->values[index].integer;
    }
    if (unknown > REFERENCES_SHOWN && used < sizeof text)
        snprintf(text + used, sizeof text - used, ", and %lu more",
                 (unsigned long)(unknown - REFERENCES_SHOWN));
    if (text[0]) return layer_refuse(in, SMA_ERROR, function, text);
    return SMA_OK;
}
