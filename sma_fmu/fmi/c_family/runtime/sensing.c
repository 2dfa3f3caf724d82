/* Temperature-sensing inverse; runtime/sensing.py (see sensing.h). */
#include "fp_contract.h"
#include "sensing.h"

#include <math.h>

#include "checks.h"
#include "constants.h"
#include "reachable_band.h"

void mixed_fractions_of_resistance(double resistance, const BranchConstants *constants,
                                   const WireParameters *params, double *xi_mf, double *xi_p)
{
    double span = params->R_MF - params->R_P;
    ResistanceBand band = band_of_branch(constants, params);
    *xi_mf = (resistance - band.hot) / span;
    *xi_p = (band.cold - resistance) / span;
}

/* (xi_MF, xi_P) moved to the nearer end of [delta, total - delta] (one is outside). */
static void clamped(double *xi_mf, double *xi_p, double total, double delta)
{
    if (!(*xi_mf >= delta)) {   /* also NaN */
        *xi_mf = delta;
        *xi_p = total - delta;
        return;
    }
    *xi_mf = total - delta;
    *xi_p = delta;
}

/* A stage of a two-stage branch: (dH/k_B [K], 1/tau_K [1/K], its share M_k of M [1]). */
typedef struct Stage {
    double energy, inverse_centre, total;
} Stage;

/* The first u [1/K] of two_stage_root.two_stage_inverse: at the steep stage's closed form
 * u_s, the steep stage's inverse of what the broad stage leaves, damped by the broad stage's
 * slope; the broad stage's inverse with the steep one saturated where the broad one alone
 * holds more than the target; the midpoint of (low, high) outside it. */
static double newton_start(double xi_mf, double xi_p, const Stage *steep, const Stage *broad,
                           double u, double low, double high)
{
    double z = broad->energy * (broad->inverse_centre - u), e, d, half, left_mf, left_p;
    double target;
    if (z > 0.0) {
        e = exp(-z);
        d = 1.0 + e;
        half = broad->total * e / d;   /* the smaller half, MF */
        left_mf = xi_mf - half;
        left_p = xi_p - broad->total / d;
    } else {
        e = exp(z);
        d = 1.0 + e;
        half = broad->total * e / d;   /* the smaller half, P */
        left_mf = xi_mf - broad->total / d;
        left_p = xi_p - half;
    }
    if (left_mf > 0.0 && left_p > 0.0) {
        target = steep->inverse_centre - log(left_p / left_mf) / steep->energy;
        u = u + (target - u) / (1.0 + broad->energy * (half / d) / steep->energy * (
            1.0 / left_p + 1.0 / left_mf));
    } else if (left_mf > 0.0) {   /* the broad stage alone holds more P: the steep one all MF */
        u = xi_mf > steep->total
            ? broad->inverse_centre - log(xi_p / (xi_mf - steep->total)) / broad->energy : low;
    } else {                      /* it holds more MF: the steep one is all P */
        u = xi_p > steep->total
            ? broad->inverse_centre - log((xi_p - steep->total) / xi_mf) / broad->energy : low;
    }
    if (!(low < u && u < high)) {
        u = 0.5 * (low + high);
    }
    return u;
}

/* One stage at u: logistic_split's halves (the same operations) and the first half's
 * derivative by -z, total e^z/(1 + e^z)^2 (two_stage_root.two_stage_inverse inlines it). */
static void split_with_slope(const Stage *stage, double u, double *mf, double *p, double *q)
{
    double z = stage->energy * (stage->inverse_centre - u), e, d;
    if (z > 0.0) {
        e = exp(-z);
        d = 1.0 + e;
        *mf = stage->total * e / d;
        *p = stage->total / d;
        *q = *mf / d;
        return;
    }
    e = exp(z);
    d = 1.0 + e;
    *mf = stage->total / d;
    *p = stage->total * e / d;
    *q = *p / d;
}

int two_stage_inverse(double xi_mf, double xi_p, double exponent, double start,
                      const TangentLine *line, double *inverse_kelvin, double *slope_out,
                      const BranchConstants *constants, SmaMessage *message)
{
    Stage first, second;
    double other, low, high, u, limit, mf, p, mf1, p1, q1, mf2, p2, q2, residual, slope;
    double step, next, tangent;
    int i;
    first.energy = constants->energy_over_kB;
    first.inverse_centre = constants->inv_centre_K;
    first.total = constants->M1;
    second.energy = constants->energy2_over_kB;
    second.inverse_centre = constants->inv_centre2_K;
    second.total = constants->M2;
    other = second.inverse_centre - exponent / second.energy;
    if (*inverse_kelvin <= other) {
        low = *inverse_kelvin;
        high = other;
    } else {
        low = other;
        high = *inverse_kelvin;
    }
    if (!(low > 0.0)) {   /* a stage alone never falls to the target: from 1/T_K = 0 */
        low = 0.0;
        two_stage_fractions(0.0, constants, &mf, &p);
        if (!(high > 0.0 && (xi_mf <= xi_p ? (mf < xi_mf) : (p > xi_p)))) {
            return sma_message_set(message, "temperature-sensing inverse diverges at Lambda = "
                                   "%.17g: the two-stage branch does not reach the target at "
                                   "any temperature (dH(f)/k_B = %.17g K, second stage %.17g K)",
                                   exponent, first.energy, second.energy);
        }
    }
    if (low < start && start < high) {   /* a caller's start (NaN: none) */
        u = start;
        if (line != NULL) {   /* the tangent's step from it, where that stays in the bracket */
            tangent = start + (line->exponent - exponent) / line->slope;
            if (low < tangent && tangent < high) {
                u = tangent;
            }
        }
    } else if (first.energy >= second.energy) {
        u = newton_start(xi_mf, xi_p, &first, &second, *inverse_kelvin, low, high);
    } else {
        u = newton_start(xi_mf, xi_p, &second, &first, other, low, high);
    }
    limit = ROOT_TOLERANCE_K / (first.energy >= second.energy ? first.energy : second.energy);
    slope = 0.0;
    for (i = 0; i < ROOT_CAP; i++) {
        split_with_slope(&first, u, &mf1, &p1, &q1);
        split_with_slope(&second, u, &mf2, &p2, &q2);
        mf = mf1 + mf2;
        p = p1 + p2;
        if (mf > 0.0 && p > 0.0) {
            residual = log(p / mf) - exponent;
            slope = (first.energy * q1 + second.energy * q2) * (1.0 / mf + 1.0 / p);
        } else {   /* a fraction underflowed (extreme values): its sign only, then halve */
            residual = p - mf;
            slope = 0.0;
        }
        if (residual > 0.0) {   /* Lambda above the target: the root is colder */
            low = u;
        } else if (residual < 0.0) {
            high = u;
        } else {
            break;
        }
        if (slope > 0.0) {
            step = residual / slope;
            next = u + step;
            if (low <= next && next <= high) {   /* next == u: the step is below u's last bit */
                if (step * step <= limit * next * next) {
                    u = next;
                    break;
                }
                if (next != u) {
                    u = next;
                    continue;
                }
            }
        }
        next = 0.5 * (low + high);
        if (!(low < next && next < high)) {   /* the bracket is two neighbouring doubles */
            break;
        }
        u = next;
    }
    *inverse_kelvin = u;
    *slope_out = slope;
    return 0;
}

int temperature_of_fractions(double xi_mf, double xi_p, const BranchConstants *constants,
                             double margin, SensedTemperature *sensed, SmaMessage *message)
{
    return temperature_near(xi_mf, xi_p, constants, margin, NAN, NULL, sensed, NULL, message);
}

int temperature_near(double xi_mf, double xi_p, const BranchConstants *constants, double margin,
                     double near, const TangentLine *line, SensedTemperature *sensed,
                     TangentLine *tangent, SmaMessage *message)
{
    double delta = margin * constants->M, exponent, inverse_kelvin, start, slope = 0.0;
    int saturated = 0;
    if (!(xi_mf >= delta && xi_p >= delta)) {
        clamped(&xi_mf, &xi_p, constants->M, delta);
        saturated = 1;
    }
    exponent = log(xi_p / xi_mf);
    inverse_kelvin = constants->inv_centre_K - exponent / constants->energy_over_kB;
    if (constants->w2 != 0.0) {
        /* 1/(near + 273.15) where that is a temperature above absolute zero, else none */
        start = near + KELVIN_OFFSET > 0.0 ? 1.0 / (near + KELVIN_OFFSET) : NAN;
        if (two_stage_inverse(xi_mf, xi_p, exponent, start, line, &inverse_kelvin, &slope,
                              constants, message)) {
            return 1;
        }
    } else if (!(inverse_kelvin > 0.0)) {
        return sma_message_set(message, "temperature-sensing inverse diverges at Lambda = %.17g: "
                               "dH(f)/k_B = %.17g K is too small for the hysteresis centre",
                               exponent, constants->energy_over_kB);
    }
    sensed->temperature = 1.0 / inverse_kelvin - KELVIN_OFFSET;
    sensed->saturated = saturated;
    if (tangent != NULL) {   /* the line at the answer: a two-stage search's, with a slope */
        tangent->exponent = slope > 0.0 ? exponent : NAN;
        tangent->slope = slope > 0.0 ? slope : NAN;
    }
    return 0;
}

int temperature_on_stack(double xi_mf, double xi_p, const BranchConstants *constants,
                         int direction, const ReversalPoint *points, size_t count, double margin,
                         SensedTemperature *sensed, size_t *kept, SmaMessage *message)
{
    double total, delta, target;
    int is_clamped = 0, heating;
    if (count == 0) {
        *kept = 0;
        return temperature_of_fractions(xi_mf, xi_p, constants, margin, sensed, message);
    }
    total = constants->M;
    delta = margin * total;
    if (!(xi_mf >= delta && xi_p >= delta)) {
        clamped(&xi_mf, &xi_p, total, delta);
        is_clamped = 1;
    }
    heating = direction == HEATING;
    target = heating ? xi_mf : xi_p;
    while (count) {
        const ReversalPoint *top = &points[count - 1];
        double value_A = value_of(top, total, heating), value_B, major_A, major_B, span, major;
        double major_mf, major_p;
        if (count >= 2) {
            const ReversalPoint *below = &points[count - 2];
            double offset;
            value_B = value_of(below, total, heating);
            offset = target - value_B;
            if (offset * (value_A - value_B) < 0.0 || offset == 0.0) {   /* at or beyond B: outer */
                count -= 2;
                continue;
            }
            major_B = major_value(below->temperature, constants, heating);
        } else {
            value_B = major_B = 0.0;
        }
        major_A = major_value(top->temperature, constants, heating);
        span = value_A - value_B;
        if (fabs(major_A - major_B) < DENOMINATOR_FLOOR || fabs(span) < DENOMINATOR_FLOOR) {
            sensed->temperature = top->temperature;
            sensed->saturated = 1;
            *kept = count;
            return 0;
        }
        major = major_B + (target - value_B) * ((major_A - major_B) / span);
        fractions_of_value(major, total, heating, &major_mf, &major_p);
        if (temperature_of_fractions(major_mf, major_p, constants, margin, sensed, message)) {
            return 1;
        }
        if (is_clamped) {
            sensed->saturated = 1;
        }
        *kept = count;
        return 0;
    }
    if (temperature_of_fractions(xi_mf, xi_p, constants, margin, sensed, message)) {
        return 1;   /* the stack emptied */
    }
    if (is_clamped) {
        sensed->saturated = 1;
    }
    *kept = 0;
    return 0;
}

int invert_on_stack(double xi_mf, double xi_p, const BranchConstants *constants, int direction,
                    const ReversalPoint *points, size_t count, double margin,
                    SensedTemperature *sensed, size_t *kept, double *assumed,
                    SmaMessage *message)
{
    if (temperature_on_stack(xi_mf, xi_p, constants, direction, points, count, margin, sensed,
                             kept, message)) {
        return 1;
    }
    if (sensed->saturated) {
        double branch_p;
        fractions_on_stack(sensed->temperature, constants, direction, points, *kept, &xi_mf,
                           &branch_p);
    }
    *assumed = xi_mf;
    return 0;
}

int sense_temperature(double resistance, double load, int direction,
                      const WireParameters *params, const ReversalPoint *reversals,
                      size_t count, SensedTemperature *sensed, SmaMessage *message)
{
    BranchConstants constants;
    double xi_mf, xi_p;
    size_t kept;
    int sign;
    if (require_positive("resistance", resistance, message)
        || direction_sign(direction, NULL, &sign, message)
        || branch_constants(load, sign, params, &constants, message)) {
        return 1;
    }
    mixed_fractions_of_resistance(resistance, &constants, params, &xi_mf, &xi_p);
    return temperature_on_stack(xi_mf, xi_p, &constants, sign, reversals, count,
                                params->saturation_margin, sensed, &kept, message);
}
