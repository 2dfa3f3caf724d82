/* Physical constants and conventions shared by every model (SI, CODATA 2018 exact values);
 * runtime/constants.py. */
#ifndef SMA_CONSTANTS_H
#define SMA_CONSTANTS_H

#define AVOGADRO 6.02214076e23        /* 1/mol */
#define BOLTZMANN 1.380649e-23        /* J/K */
#define MOLAR_MASS_TI 47.867e-3       /* kg/mol */
#define MOLAR_MASS_NI 58.6934e-3      /* kg/mol */
#define STANDARD_GRAVITY 9.80665      /* m/s^2: a hung mass f [kg] pulls with g*f [N] */
#define KELVIN_OFFSET 273.15          /* K: T_K = T_degC + KELVIN_OFFSET */
#define SMA_PI 3.141592653589793      /* Python's math.pi (C99 has no M_PI) */

#define HEATING 1                     /* direction d = sgn(dT/dt) while heating */
#define COOLING (-1)                  /* direction d while cooling */

#endif
