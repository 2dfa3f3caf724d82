/* The stroke map; runtime/stroke.py (see stroke.h). */
#include "fp_contract.h"
#include "stroke.h"

#include <math.h>

#include "sensing.h"

void stroke_map_init(StrokeMap *map, const WireParameters *params, double start_length)
{
    map->params = *params;
    map->start_length = start_length;
    map->thermal = params->terms.alpha_P != 0.0 || params->terms.alpha_MF != 0.0;
    branch_cache_init(&map->branches);
    map->has_last = 0;
    map->has_ends = 0;
}

/* plant.py's branch_length: x [m] of the fractions at `temperature` on the branch */
static double branch_length(double temperature, double xi_p, double xi_m, double xi_f,
                            const BranchConstants *c, const WireParameters *p)
{
    if (!c->has_lengths) {
        return p->l_P * xi_p + p->l_M * xi_m + p->l_F * xi_f;
    }
    return wire_length(temperature, xi_p, xi_m, xi_f, c->length_M, c->length_F, p);
}

/* xi_MF [1] whose length at `temperature` is `length`, clamped into [delta, M - delta] */
static double fraction_at(const StrokeMap *map, double temperature, double length,
                          const BranchConstants *c, int *clamped)
{
    const WireParameters *p = &map->params;
    double total = c->M;
    double hot = branch_length(temperature, total, 0.0, c->xi_F_min, c, p);
    double cold = branch_length(temperature, 0.0, 0.5 * total, c->xi_F_min + 0.5 * total, c, p);
    double xi_mf = total * (length - hot) / (cold - hot);
    double delta = p->saturation_margin * total;
    *clamped = 1;
    if (!(xi_mf >= delta)) {   /* also NaN */
        return delta;
    }
    if (!(xi_mf <= total - delta)) {
        return total - delta;
    }
    *clamped = 0;
    return xi_mf;
}

static int branch_temperature(double xi_mf, const BranchConstants *c, double margin,
                              double *temperature, SmaMessage *message)
{
    SensedTemperature sensed;
    if (temperature_of_fractions(xi_mf, c->M - xi_mf, c, margin, &sensed, message)) {
        return 1;
    }
    *temperature = sensed.temperature;
    return 0;
}

static int solve(StrokeMap *map, double stroke, double load, int direction,
                 const BranchConstants *c, StrokeTarget *out, SmaMessage *message)
{
    const WireParameters *p = &map->params;
    double total = c->M, length = map->start_length - stroke;
    double margin = p->saturation_margin, delta = margin * total;
    double xi_mf, temperature, proposal = 0.0;
    double xi_p, xi_m, xi_f;
    int clamped, round;
    if (!map->thermal) {   /* x does not depend on T: one affine solve */
        xi_mf = fraction_at(map, c->centre, length, c, &clamped);
        if (branch_temperature(xi_mf, c, margin, &temperature, message)) return 1;
    } else {
        double low, high, before = 0.0, residual, residual_before = 0.0, step;
        int has_before = 0;
        if (!map->has_ends || map->ends_load != load || map->ends_direction != direction) {
            if (branch_temperature(total - delta, c, margin, &map->ends_low, message)
                || branch_temperature(delta, c, margin, &map->ends_high, message)) {
                map->has_ends = 0;
                return 1;
            }
            map->has_ends = 1;
            map->ends_load = load;
            map->ends_direction = direction;
        }
        low = map->ends_low;
        high = map->ends_high;
        temperature = c->centre;
        if (low > temperature) temperature = low;     /* min(max(centre, low), high) */
        if (high < temperature) temperature = high;
        xi_mf = 0.0;
        clamped = 0;
        for (round = 0; round < ROOT_CAP; ++round) {
            xi_mf = fraction_at(map, temperature, length, c, &clamped);
            if (branch_temperature(xi_mf, c, margin, &proposal, message)) return 1;
            residual = proposal - temperature;
            if (fabs(residual) <= ROOT_TOLERANCE_K || high - low <= ROOT_TOLERANCE_K) {
                break;
            }
            if (residual > 0.0) {
                low = temperature;
            } else {
                high = temperature;
            }
            if (!has_before || residual == residual_before) {   /* the fixed-point step */
                step = proposal;
            } else {   /* the secant through the last two residuals */
                step = temperature - residual * (temperature - before) / (residual - residual_before);
            }
            before = temperature;
            residual_before = residual;
            has_before = 1;
            temperature = low < step && step < high ? step : 0.5 * (low + high);
        }
        temperature = proposal;
    }
    xi_p = total - xi_mf;
    xi_m = 0.5 * xi_mf;
    xi_f = c->xi_F_min + 0.5 * xi_mf;
    out->R_ref = p->R_P * xi_p + p->R_M * xi_m + p->R_F * xi_f;
    out->stroke = clamped ? map->start_length - branch_length(temperature, xi_p, xi_m, xi_f, c, p)
                          : stroke;
    out->temperature = temperature;
    out->clamped = clamped;
    return 0;
}

int stroke_map_target(StrokeMap *map, double stroke, double load, int direction,
                      StrokeTarget *out, SmaMessage *message)
{
    BranchConstants constants;
    if (map->has_last && stroke == map->last_stroke && load == map->last_load
        && direction == map->last_direction) {
        *out = map->last;
        return 0;
    }
    if (branch_cache_get(&map->branches, &map->params, load, direction, &constants, message)
        || solve(map, stroke, load, direction, &constants, out, message)) {
        return 1;
    }
    map->has_last = 1;
    map->last_stroke = stroke;
    map->last_load = load;
    map->last_direction = direction;
    map->last = *out;
    return 0;
}
