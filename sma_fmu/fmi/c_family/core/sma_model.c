/* Model-free helpers the adapters share (declared in sma_model.h). */
#include "fp_contract.h"
#include <math.h>

#include "sma_model.h"
#include "scenario_signals.h"  /* GRID_TOLERANCE */

double sma_nominal_step(SmaRun *run, double step_size)
{
    double first = run->first_step;
    if (!(first > 0.0)) run->first_step = first = step_size;
    return fabs(step_size - first) <= GRID_TOLERANCE * first ? first : step_size;
}
