/* A PWM wire driver; runtime/pwm.py (see pwm.h). */
#include "fp_contract.h"
#include "pwm.h"

#include <math.h>

#include "checks.h"
#include "state_entries.h"

#define PWM_STATE_SIZE 4
#define TWO_TO_53 9007199254740992.0

const char *const DRIVE_KINDS[DRIVE_KIND_COUNT] = {"power", "pwm"};

/* Python's max(a, b) and min(a, b): the first argument unless the second is larger/smaller
 * (so NaN and signed zeros come out as in Python). */
static double py_max(double a, double b)
{
    return b > a ? b : a;
}

static double py_min(double a, double b)
{
    return b < a ? b : a;
}

/* float(index) of Python's int: the double nearest base - minus_one (one rounding). */
static double index_value(PwmIndex index)
{
    return index.minus_one ? index.base - 1.0 : index.base;
}

/* Python's int - 1 kept exact: folded into base where base - 1 is a double (base in
 * (-2^53, 2^53]; -2^53 - 1 is not one). */
static PwmIndex index_less_one(PwmIndex index)
{
    if (index.minus_one == 0 && index.base > -TWO_TO_53 && index.base <= TWO_TO_53) {
        index.base -= 1.0;
    } else {
        index.minus_one = 1;
    }
    return index;
}

/* (a - a_minus) <= b exactly, for integer-valued a, b: a - b is an integer, so its rounded
 * double compares with the small integer a_minus as the exact difference does. */
static int index_at_most(PwmIndex a, PwmIndex b)
{
    return a.base - b.base <= (double)a.minus_one - (double)b.minus_one;
}

static int index_equal(PwmIndex a, PwmIndex b)
{
    return a.base - b.base == (double)a.minus_one - (double)b.minus_one;
}

/* The double nearest the exact sum of three doubles (math.fsum's algorithm: Shewchuk's
 * partials and the half-even correction); 1 when it overflows. This is Python's
 * float(int) of an exact integer expression. */
static int exact_sum(const double terms[3], double *out)
{
    double partials[3], x, y, hi, lo = 0.0, yr;
    int used = 0, term, i, j;
    for (term = 0; term < 3; term++) {
        x = terms[term];
        i = 0;
        for (j = 0; j < used; j++) {
            y = partials[j];
            if (fabs(x) < fabs(y)) {
                double swap = x;
                x = y;
                y = swap;
            }
            hi = x + y;
            lo = y - (hi - x);
            if (lo != 0.0) {
                partials[i++] = lo;
            }
            x = hi;
        }
        if (!isfinite(x)) {
            return 1;
        }
        partials[i] = x;
        used = i + 1;
    }
    hi = 0.0;
    if (used > 0) {
        int n = used - 1;
        hi = partials[n];
        lo = 0.0;
        while (n > 0) {
            x = hi;
            y = partials[--n];
            hi = x + y;
            yr = hi - x;
            lo = y - yr;
            if (lo != 0.0) {
                break;
            }
        }
        if (n > 0 && ((lo < 0.0 && partials[n - 1] < 0.0) || (lo > 0.0 && partials[n - 1] > 0.0))) {
            y = lo * 2.0;
            x = hi + y;
            yr = x - hi;
            if (y == yr) {
                hi = x;
            }
        }
    }
    if (!isfinite(hi)) {
        return 1;
    }
    *out = hi;
    return 0;
}

int pwm_driver_init(PwmDriver *driver, double frequency_Hz, double peak_W, SmaMessage *message)
{
    if (require_positive("frequency_Hz", frequency_Hz, message)) {
        return 1;
    }
    if (!(MIN_FREQUENCY_HZ <= frequency_Hz && frequency_Hz <= MAX_FREQUENCY_HZ)) {
        return sma_message_set(message, "frequency_Hz must be in [%g, %g] Hz, got %.17g",
                               MIN_FREQUENCY_HZ, MAX_FREQUENCY_HZ, frequency_Hz);
    }
    if (require_positive("peak_W", peak_W, message)) {
        return 1;
    }
    driver->frequency = frequency_Hz;
    driver->peak = peak_W;
    driver->period = 1.0 / driver->frequency;
    driver->has_held = 0;
    driver->held_index.base = 0.0;
    driver->held_index.minus_one = 0;
    driver->held_duty = 0.0;
    driver->power = 0.0;
    driver->limited = 0;
    return 0;
}

void pwm_driver_set_limit(PwmDriver *driver, const DriveLimit *limit)
{
    driver->limit = *limit;
    driver->limited = limit->limited;
}

/* (j, starts): the period containing time_s [s] and whether it starts there; refused
 * (Python's OverflowError) when time_s * frequency is not finite. */
static int period_index(const PwmDriver *driver, double time_s, PwmIndex *index, int *starts,
                        SmaMessage *message)
{
    double position = time_s * driver->frequency;
    double nearest;
    if (!isfinite(position)) {
        return sma_message_set(message, "cannot convert float infinity to integer: the period "
                               "index time * frequency_Hz overflows at time = %.17g s", time_s);
    }
    nearest = nearbyint(position);
    index->minus_one = 0;
    if (fabs(position - nearest) <= PERIOD_TOLERANCE * py_max(1.0, fabs(position))) {
        index->base = nearest + 0.0;       /* + 0.0: Python's int has no -0 */
        *starts = 1;
    } else {
        index->base = floor(position) + 0.0;
        *starts = 0;
    }
    return 0;
}

double pwm_driver_duty_of(const PwmDriver *driver, double demand_W)
{
    double duty = demand_W / driver->peak;
    return !(duty > 0.0) ? 0.0 : (duty > 1.0 ? 1.0 : duty);
}

/* On-time [s] of period `index` with `duty` inside [start, end). */
static double on_time(const PwmDriver *driver, PwmIndex index, double duty, double start,
                      double end)
{
    double begin = index_value(index) * driver->period;
    return py_max(0.0, py_min(begin + duty * driver->period, end) - py_max(begin, start));
}

int pwm_driver_step(PwmDriver *driver, double demand_W, double time_s, double step_size,
                    double *power, SmaMessage *message)
{
    return pwm_driver_step_limited(driver, demand_W, time_s, step_size, NAN, power, message);
}

int pwm_driver_step_limited(PwmDriver *driver, double demand_W, double time_s, double step_size,
                            double resistance, double *power, SmaMessage *message)
{
    double end, duty, first_duty, last_duty, on, on_power;
    PwmIndex first, last;
    int starts, last_starts;
    if (fast_finite("P_demand", demand_W, message) || fast_finite("time", time_s, message)
        || fast_positive("step_size", step_size, message)) {
        return 1;
    }
    on_power = driver->peak;
    if (driver->limited) {
        if (fast_positive("R", resistance, message)) {
            return 1;
        }
        on_power = drive_limit_apply(&driver->limit, on_power, resistance);
    }
    end = time_s + step_size;
    duty = pwm_driver_duty_of(driver, demand_W);
    if (period_index(driver, time_s, &first, &starts, message)) {
        return 1;
    }
    if (!starts && driver->has_held && index_equal(driver->held_index, first)) {
        first_duty = driver->held_duty;
    } else {
        first_duty = duty;
    }
    if (period_index(driver, end, &last, &last_starts, message)) {
        return 1;
    }
    if (last_starts) {
        last = index_less_one(last);   /* the period starting at the step's end is not in it */
    }
    if (index_at_most(last, first)) {
        on = on_time(driver, first, first_duty, time_s, end);
        last = first;
        last_duty = first_duty;
    } else {
        /* whole periods inside the step, all of duty `duty`: float(last - first - 1) */
        double terms[3], full;
        terms[0] = last.base;
        terms[1] = -first.base;
        terms[2] = -1.0 - (double)last.minus_one + (double)first.minus_one;
        if (exact_sum(terms, &full)) {
            return sma_message_set(message, "int too large to convert to float: the periods "
                                   "from time = %.17g s to %.17g s", time_s, end);
        }
        on = on_time(driver, first, first_duty, time_s, end);
        on += full * duty * driver->period;
        on += on_time(driver, last, duty, time_s, end);
        last_duty = duty;
    }
    driver->has_held = 1;
    driver->held_index = last;
    driver->held_duty = last_duty;
    driver->power = on_power * py_min(1.0, on / step_size);
    *power = driver->power;
    return 0;
}

size_t pwm_driver_state_size(const PwmDriver *driver)
{
    (void)driver;
    return PWM_STATE_SIZE;
}

void pwm_driver_state_write(const PwmDriver *driver, double *out)
{
    out[0] = driver->has_held ? driver->held_index.base : SMA_STATE_NONE;
    out[1] = driver->has_held ? (double)driver->held_index.minus_one : 0.0;
    out[2] = driver->has_held ? driver->held_duty : SMA_STATE_NONE;
    out[3] = driver->power;
}

int pwm_driver_state_read(PwmDriver *driver, const double *in, size_t count,
                          SmaMessage *message)
{
    int has_held;
    if (read_entries(count, PWM_STATE_SIZE, "PWM state", message)) {
        return 1;
    }
    has_held = !sma_state_is_none(in[0]);
    if (!has_held) {
        if (in[1] != 0.0 || !sma_state_is_none(in[2])) {
            return sma_message_set(message, "held must be None or [period index, duty], got "
                                   "None with minus_one %.17g and duty %.17g", in[1], in[2]);
        }
    } else {
        if (!isfinite(in[0]) || in[0] != floor(in[0]) || !(in[1] == 0.0 || in[1] == 1.0)) {
            return sma_message_set(message, "held must be None or [period index, duty], got "
                                   "[%.17g - %.17g, %.17g]", in[0], in[1], in[2]);
        }
        if (fast_finite("held duty", in[2], message)) {
            return 1;
        }
        if (!(0.0 <= in[2] && in[2] <= 1.0)) {
            return sma_message_set(message, "held duty must be in [0, 1], got %.17g", in[2]);
        }
    }
    if (fast_finite("power", in[3], message)) {
        return 1;
    }
    if (!(0.0 <= in[3] && in[3] <= driver->peak)) {
        return sma_message_set(message, "power must be in [0, peak_W], got %.17g", in[3]);
    }
    driver->has_held = has_held;
    driver->held_index.base = has_held ? in[0] : 0.0;
    driver->held_index.minus_one = has_held ? (int)in[1] : 0;
    driver->held_duty = has_held ? in[2] : 0.0;
    driver->power = in[3];
    return 0;
}
