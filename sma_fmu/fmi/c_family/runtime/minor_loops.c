/* Minor loops with return-point memory; runtime/minor_loops.py (see minor_loops.h). */
#include "fp_contract.h"
#include "minor_loops.h"

#include <math.h>
#include <string.h>

#include "constants.h"

void push_reversal(ReversalPoint *points, size_t *count, double temperature, double xi_mf,
                   size_t depth)
{
    points[*count].temperature = temperature;
    points[*count].xi_MF = xi_mf;
    *count += 1;
    if (*count > depth) {
        memmove(points, points + 2, (*count - 2) * sizeof *points);
        *count -= 2;
    }
}

size_t wipe_out(ReversalPoint *points, size_t *count, double temperature, int direction)
{
    size_t dropped = 0;
    int heating = direction == HEATING;
    while (*count >= 2) {
        double bound = points[*count - 2].temperature;
        if (heating ? (temperature >= bound) : (temperature <= bound)) {
            *count -= 2;
            dropped += 2;
        } else {
            break;
        }
    }
    return dropped;
}

double major_value(double temperature, const BranchConstants *constants, int heating)
{
    double xi_mf, xi_p;
    branch_fractions(temperature, constants, &xi_mf, &xi_p);
    return heating ? xi_mf : xi_p;
}

double value_of(const ReversalPoint *point, double total, int heating)
{
    return heating ? point->xi_MF : total - point->xi_MF;
}

void fractions_of_value(double value, double total, int heating, double *xi_mf, double *xi_p)
{
    if (heating) {
        *xi_mf = value;
        *xi_p = total - value;
    } else {
        *xi_mf = total - value;
        *xi_p = value;
    }
}

Branch branch_of(const ReversalPoint *points, size_t count, const BranchConstants *constants,
                 int direction)
{
    int heating = direction == HEATING;
    double total = constants->M;
    ReversalPoint top = points[count - 1];
    double value_A = value_of(&top, total, heating);
    double major_A = major_value(top.temperature, constants, heating);
    double value_B, major_B, denominator;
    Branch branch;
    if (count >= 2) {
        ReversalPoint below = points[count - 2];
        value_B = value_of(&below, total, heating);
        major_B = major_value(below.temperature, constants, heating);
    } else {   /* the end of the major loop */
        value_B = major_B = 0.0;
    }
    denominator = major_A - major_B;
    if (fabs(denominator) < DENOMINATOR_FLOOR) {
        branch.value_B = value_A;
        branch.ratio = 0.0;
        branch.major_B = 0.0;
        return branch;
    }
    branch.value_B = value_B;
    branch.ratio = (value_A - value_B) / denominator;
    branch.major_B = major_B;
    return branch;
}

void fractions_on_branch(double temperature, const BranchConstants *constants, int direction,
                         const Branch *branch, double *xi_mf, double *xi_p)
{
    int heating;
    double major_mf, major_p, total, value;
    branch_fractions(temperature, constants, &major_mf, &major_p);
    if (branch == NULL) {
        *xi_mf = major_mf;
        *xi_p = major_p;
        return;
    }
    heating = direction == HEATING;
    total = constants->M;
    value = branch->value_B + branch->ratio * ((heating ? major_mf : major_p) - branch->major_B);
    value = value < 0.0 ? 0.0 : (value > total ? total : value);
    fractions_of_value(value, total, heating, xi_mf, xi_p);
}

void fractions_on_stack(double temperature, const BranchConstants *constants, int direction,
                        const ReversalPoint *points, size_t count, double *xi_mf,
                        double *xi_p)
{
    Branch branch;
    if (count == 0) {
        fractions_on_branch(temperature, constants, direction, NULL, xi_mf, xi_p);
        return;
    }
    branch = branch_of(points, count, constants, direction);
    fractions_on_branch(temperature, constants, direction, &branch, xi_mf, xi_p);
}

int read_points(const double *pairs, size_t count, size_t depth, const char *name,
                ReversalPoint *out, SmaMessage *message)
{
    size_t index;
    if (name == NULL) {
        name = "reversals";
    }
    if (count > depth) {
        return sma_message_set(message, "%s must be a list of at most %lu [T, xi_MF] pairs, "
                               "got %lu pairs", name, (unsigned long)depth,
                               (unsigned long)count);
    }
    for (index = 0; index < count; index++) {
        double temperature = pairs[2 * index], xi_mf = pairs[2 * index + 1];
        if (!(-273.15 < temperature && temperature < HUGE_VAL && 0.0 <= xi_mf && xi_mf <= 1.0)) {
            return sma_message_set(message, "%s[%lu] = [%.17g, %.17g]: T must be finite above "
                                   "-273.15 degC and xi_MF in [0, 1]", name,
                                   (unsigned long)index, temperature, xi_mf);
        }
    }
    if (out != NULL) {
        for (index = 0; index < count; index++) {
            out[index].temperature = pairs[2 * index];
            out[index].xi_MF = pairs[2 * index + 1];
        }
    }
    return 0;
}
