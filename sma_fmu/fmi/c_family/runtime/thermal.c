/* First-order thermal model; runtime/thermal.py (see thermal.h). */
#include "fp_contract.h"
#include "thermal.h"

#include <math.h>

double thermal_gain(double h_c, double A_s)
{
    return 1.0 / (h_c * A_s);
}

double thermal_time_constant(double mass, double c_p, double h_c, double A_s)
{
    return mass * c_p / (h_c * A_s);
}

double step_decay(double step_size, double time_constant)
{
    return exp(-step_size / time_constant);
}

double thermal_step(double temperature, double power, double T_room, double gain, double decay)
{
    return T_room + (temperature - T_room) * decay + gain * power * (1.0 - decay);
}

double power_to_reach(double temperature, double target, double T_room, double gain,
                      double decay)
{
    return (target - T_room - (temperature - T_room) * decay) / (gain * (1.0 - decay));
}
