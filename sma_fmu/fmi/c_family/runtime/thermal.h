/* First-order thermal model of the Joule-heated wire (spec section 9, paper eqs. 43-44);
 * runtime/thermal.py:  m cp dT/dt = u - hc As (T - Troom),  G_th(s) = K_th / (tau_th s + 1). */
#ifndef SMA_THERMAL_H
#define SMA_THERMAL_H

/* Static gain K_th = 1/(hc As) [K/W] from h_c [W/(m2.K)] and A_s [m2]. */
double thermal_gain(double h_c, double A_s);
/* Time constant tau_th = m cp/(hc As) [s] from mass [kg] and c_p [J/(kg.K)]. */
double thermal_time_constant(double mass, double c_p, double h_c, double A_s);
/* Zero-order-hold decay factor exp(-h/tau_th) [1] for a step h [s]. */
double step_decay(double step_size, double time_constant);
/* Exact temperature [degC] after one step with the power [W] held:
 * T+ = Troom + (T - Troom) decay + K_th u (1 - decay). */
double thermal_step(double temperature, double power, double T_room, double gain, double decay);
/* The power u [W] that takes the temperature to `target` [degC] in one step (the inverse). */
double power_to_reach(double temperature, double target, double T_room, double gain,
                      double decay);

#endif
