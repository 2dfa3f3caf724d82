/* The driver's current and voltage limit; runtime/drive_limit.py (see drive_limit.h). */
#include "fp_contract.h"
#include "drive_limit.h"

#include <math.h>

#include "checks.h"
#include "state_entries.h"

int drive_limit_init(DriveLimit *limit, double I_max_A, double V_max_V, SmaMessage *message)
{
    if (require_nonnegative("I_max_A", I_max_A, message)
        || require_nonnegative("V_max_V", V_max_V, message)) {
        return 1;
    }
    limit->I_max = I_max_A;
    limit->V_max = V_max_V;
    limit->current_squared = I_max_A != 0.0 ? I_max_A * I_max_A : HUGE_VAL;
    limit->voltage_squared = V_max_V != 0.0 ? V_max_V * V_max_V : HUGE_VAL;
    limit->limited = I_max_A != 0.0 || V_max_V != 0.0;
    return 0;
}

double drive_limit_cap(const DriveLimit *limit, double resistance)
{
    double by_current = limit->current_squared * resistance;
    double by_voltage = limit->voltage_squared / resistance;
    return by_current <= by_voltage ? by_current : by_voltage;
}

double drive_limit_apply(const DriveLimit *limit, double power, double resistance)
{
    double cap = drive_limit_cap(limit, resistance);
    return power <= cap ? power : cap;
}

void linear_driver_init(LinearDriver *driver, const DriveLimit *limit)
{
    driver->limit = *limit;
    driver->power = 0.0;
}

int linear_driver_step(LinearDriver *driver, double demand_W, double time_s, double step_size,
                       double resistance, double *power, SmaMessage *message)
{
    if (fast_finite("P_demand", demand_W, message) || fast_finite("time", time_s, message)
        || fast_positive("step_size", step_size, message)) {
        return 1;
    }
    if (driver->limit.limited) {
        if (fast_positive("R", resistance, message)) {
            return 1;
        }
        demand_W = drive_limit_apply(&driver->limit, demand_W, resistance);
    }
    driver->power = demand_W;
    *power = demand_W;
    return 0;
}

size_t linear_driver_state_size(const LinearDriver *driver)
{
    (void)driver;
    return 1;
}

void linear_driver_state_write(const LinearDriver *driver, double *out)
{
    out[0] = driver->power;
}

int linear_driver_state_read(LinearDriver *driver, const double *in, size_t count,
                             SmaMessage *message)
{
    if (read_entries(count, 1, "driver state", message)
        || read_number(in[0], "power", -HUGE_VAL, HUGE_VAL, "W", message)) {
        return 1;
    }
    driver->power = in[0];
    return 0;
}
