/* The reachable resistance band; runtime/reachable_band.py (see reachable_band.h). */
#include "fp_contract.h"
#include "reachable_band.h"

#include "constants.h"

ResistanceBand band_of_branch(const BranchConstants *constants, const WireParameters *params)
{
    ResistanceBand band;
    band.hot = params->R_P + constants->xi_F_min * (params->R_F - params->R_P);
    band.cold = band.hot + constants->M * (params->R_MF - params->R_P);
    return band;
}

int reachable_band(double load, const WireParameters *params, ResistanceBand *band,
                   SmaMessage *message)
{
    BranchConstants constants;
    if (branch_constants(load, HEATING, params, &constants, message)) {
        return 1;
    }
    *band = band_of_branch(&constants, params);
    return 0;
}
