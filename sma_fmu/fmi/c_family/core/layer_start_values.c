/* Packed start values: resources/start_values.json, which `sma-fmu export` writes into every
 * FMU it packs (python_family/slave_support/start_values.py, systems/packed.py), read when the instance is
 * created, as the pythonfmu slaves read it (SlaveInterface): each parameter it names starts
 * with its value. Choice: the native FMU reads the same file as the pythonfmu one (with the
 * runtime's JSON reader, json_text.c), so packing needs nothing per family and the model
 * description's start attributes and the file cannot disagree for one family only.
 * A file that is not such a document (read by layer_start_file.c: a regular file, bounded,
 * strict UTF-8), or a value that is not of the parameter's type, makes fmi2Instantiate fail
 * naming the file and the parameter, as in the pythonfmu FMUs. */
#include "fp_contract.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "layer.h"
#include "json_text.h"

#define START_VALUES_FILE "start_values.json"
#define BUILD_STARTS_FILE "model_starts.json"

static const char *const KIND_NAMES[] = {"Real", "Integer", "Boolean", "String"};

/* start_values.start_value: `value` as the start of `v`, into *out; else why (naming `file`). */
static int start_value(const char *file, const SmaVariable *v, const JsonValue *value,
                       SmaValue *out, char *why, size_t size)
{
    char shown[200];
    int ok = 0;
    if (v->kind == SMA_REAL && value->kind == JSON_NUMBER && isfinite(value->number)) {
        out->real = value->number;
        ok = 1;
    } else if (v->kind == SMA_INTEGER && value->kind == JSON_NUMBER && value->integer &&
               value->number >= -2147483648.0 && value->number < 2147483648.0) {
        out->integer = (int)value->number;
        ok = 1;
    } else if (v->kind == SMA_BOOLEAN && (value->kind == JSON_TRUE || value->kind == JSON_FALSE)) {
        out->integer = value->kind == JSON_TRUE;
        ok = 1;
    } else if (v->kind == SMA_STRING && value->kind == JSON_STRING &&
               strlen(value->text) == value->length) {
        char *copy = (char *)malloc(value->length + 1);
        if (!copy) { snprintf(why, size, "out of memory"); return 1; }
        memcpy(copy, value->text, value->length + 1);
        free(out->text);
        out->text = copy;
        ok = 1;
    }
    if (ok) return 0;
    json_value_repr(value, shown, sizeof shown);
    snprintf(why, size, "%s: %s = %s is not a valid %s start value", file, v->name,
             shown, KIND_NAMES[v->kind]);
    return 1;
}

/* Read resources/<file> as a JSON object holding an object "values": 1 with *document parsed
 * and *values in it (free the document), 0 when the file is missing, -1 with `why` set. */
static int read_values_document(const Instance *in, const char *file, char *path,
                                size_t path_size, JsonValue *document, const JsonValue **values,
                                char *why, size_t size)
{
    char error[400];
    int missing;
    char *text;
    snprintf(path, path_size, "%s/%s", in->resources, file);
    text = layer_start_file(path, &missing, why, size);
    if (!text) return missing ? 0 : -1;
    if (json_text_parse(text, document, error, sizeof error)) {
        free(text);
        snprintf(why, size, "%.300s: cannot be read (%s)", path, error);
        return -1;
    }
    free(text);
    *values = document->kind == JSON_OBJECT ? json_object_get(document, "values") : NULL;
    if (!*values || (*values)->kind != JSON_OBJECT) {
        json_value_free(document);
        snprintf(why, size, "%.300s: must be a JSON object with an object 'values'", path);
        return -1;
    }
    return 1;
}

int layer_packed_start_values(Instance *in, char *why, size_t size)
{
    char path[4200];
    int failed = 0, found;
    size_t i, index;
    JsonValue document;
    const JsonValue *values;
    if (!in->resources) return 0;
    found = read_values_document(in, START_VALUES_FILE, path, sizeof path, &document, &values,
                                 why, size);
    if (found <= 0) return found < 0;   /* no packed values: nothing to do */
    for (i = 0; i < values->count && !failed; ++i) {
        const JsonValue *key = &values->keys[i];
        for (index = 0; index < in->model->count; ++index) {
            const SmaVariable *v = &in->model->variables[index];
            if (v->causality == SMA_PARAMETER && json_string_is(key, v->name)) {
                failed = start_value(START_VALUES_FILE, v, &values->items[i], &in->values[index],
                                     why, size);
                break;
            }
        }
    }
    json_value_free(&document);
    return failed;
}

/* The build's starts: {"structure", "token", "wire_digest": the build's identity, "values":
 * {every variable: its start; null: an optional wire parameter not given, NaN},
 * "wire_defaults": [numbers or null, PARAMETER_SPECS order]}, written by `sma-fmu build --native` beside parameters.json
 * (packaging/c_family_build.py). Choice: the binary holds none of a parameter file's values,
 * so one binary serves every parameter file and can be built once (reproducible.py); the
 * model description's start attributes are written from the same numbers. */
static int build_wire_defaults(Instance *in, const JsonValue *wire, const char *path, char *why,
                               size_t size)
{
    size_t i;
    if (!wire || wire->kind != JSON_ARRAY) {
        snprintf(why, size, "%.300s: must hold an array 'wire_defaults'", path);
        return 1;
    }
    free(in->wire_defaults);
    in->wire_defaults = (double *)malloc((wire->count ? wire->count : 1) * sizeof(double));
    in->run.wire_defaults = in->wire_defaults;
    in->run.wire_count = 0;
    if (!in->wire_defaults) { snprintf(why, size, "out of memory"); return 1; }
    for (i = 0; i < wire->count; ++i) {
        const JsonValue *item = &wire->items[i];
        if (item->kind != JSON_NULL && !(item->kind == JSON_NUMBER && isfinite(item->number))) {
            snprintf(why, size, "%.300s: wire_defaults[%lu] is neither a finite number nor null",
                     path, (unsigned long)i);
            return 1;
        }
        in->wire_defaults[i] = item->kind == JSON_NULL ? NAN : item->number;
    }
    in->run.wire_count = wire->count;
    return 0;
}

/* The text member `key` of the build's starts into `out` (at most size - 1 bytes); 0 with why
 * when it is missing, not a string or too long. */
static int identity_text(const JsonValue *document, const char *key, const char *path, char *out,
                         size_t out_size, char *why, size_t size)
{
    const JsonValue *value = json_object_get(document, key);
    if (!value || value->kind != JSON_STRING || value->length >= out_size ||
        strlen(value->text) != value->length) {
        snprintf(why, size, "%.300s: must hold a string '%s' (the build's identity)", path, key);
        return 0;
    }
    memcpy(out, value->text, value->length + 1);
    return 1;
}

/* The build's identity: the structure it was built for must be this binary's, then its
 * token and wire digest are kept (layer_instantiate checks the host's token against them).
 * Choice: the binary holds no wire (one binary serves every parameter file), so the token of
 * a build is {structure + wire} and the resources say which wire they hold. */
static int build_identity(Instance *in, const JsonValue *document, const char *path, char *why,
                          size_t size)
{
    char structure[80];
    if (!identity_text(document, "structure", path, structure, sizeof structure, why, size) ||
        !identity_text(document, "token", path, in->build_token, sizeof in->build_token, why, size) ||
        !identity_text(document, "wire_digest", path, in->wire_digest, sizeof in->wire_digest,
                       why, size))
        return 1;
    if (strcmp(structure, in->model->guid) != 0) {
        snprintf(why, size, "%.300s: the resources were built for another model or version "
                 "(structure %s; this binary is %s): point the resource location at this FMU's "
                 "own resources folder", path, structure, in->model->guid);
        return 1;
    }
    return 0;
}

int layer_build_starts(Instance *in, char *why, size_t size)
{
    char path[4200];
    int failed = 0, found;
    size_t i, index;
    JsonValue document;
    const JsonValue *values;
    if (!in->resources) return 0;
    found = read_values_document(in, BUILD_STARTS_FILE, path, sizeof path, &document, &values,
                                 why, size);
    if (found == 0) snprintf(why, size, "%.300s: missing (the FMU's start values)", path);
    if (found <= 0) return 1;
    failed = build_identity(in, &document, path, why, size);
    for (index = 0; index < in->model->count && !failed; ++index) {
        const SmaVariable *v = &in->model->variables[index];
        for (i = 0; i < values->count; ++i)
            if (json_string_is(&values->keys[i], v->name)) break;
        if (i == values->count) {
            snprintf(why, size, "%.300s: no start value of %s", path, v->name);
            failed = 1;
        } else if (v->kind == SMA_REAL && v->wire >= 0 && values->items[i].kind == JSON_NULL) {
            in->values[index].real = NAN;   /* an optional wire parameter not given */
        } else {
            failed = start_value(BUILD_STARTS_FILE, v, &values->items[i], &in->values[index], why,
                                 size);
        }
    }
    if (!failed)
        failed = build_wire_defaults(in, json_object_get(&document, "wire_defaults"), path, why, size);
    json_value_free(&document);
    return failed;
}
