/* PV yield per kWp, PVWatts-style as pvlib computes it (shared by kernels
 * and C; doc/insolation.md, "PV yield"): the cell temperature from the
 * plane-of-array irradiance, air temperature and wind (pvlib.temperature.
 * faiman or sapm_cell), and pvlib.pvsystem.pvwatts_dc's temperature
 * coefficient against 25 C. Irradiance W/m^2, temperatures C, wind m/s. */
#ifndef SS_PV_H
#define SS_PV_H

#include "ss_compat.h"

#define SS_PV_CELL_TEMP_FAIMAN 0
#define SS_PV_CELL_TEMP_SAPM 1

/* Faiman (2008) with pvlib's default u0 = 25, u1 = 6.84 W/(m^2 K). */
SS_FN float ss_faiman_cell_temp(float poa, float temp_air, float wind)
{
    return temp_air + poa / (25.0f + 6.84f * wind);
}

/* King et al. (2004) SAPM, open rack glass/glass (pvlib's
 * 'open_rack_glass_glass': a = -3.47, b = -0.0594, deltaT = 3). */
SS_FN float ss_sapm_cell_temp(float poa, float temp_air, float wind)
{
    float module = poa * SS_EXP(-3.47f - 0.0594f * wind) + temp_air;
    return module + poa / 1000.0f * 3.0f;
}

/* DC power per kW of nameplate (pvwatts_dc with pdc0 = 1): the plane-of-
 * array irradiance in suns, derated by gamma_pdc (1/K) away from 25 C. */
SS_FN float ss_pvwatts_dc_per_kwp(float poa, float temp_cell, float gamma_pdc)
{
    return poa / 1000.0f * (1.0f + gamma_pdc * (temp_cell - 25.0f));
}

/* AC power of an inverter whose DC input limit is pdc0 (same unit as pdc),
 * as pvlib.inverter.pvwatts: efficiency eta_nom / 0.9637 (-0.0162 zeta -
 * 0.0059 / zeta + 0.9858) at zeta = pdc / pdc0, clipped at the AC rating
 * eta_nom pdc0 and at 0. */
SS_FN float ss_pvwatts_ac(float pdc, float pdc0, float eta_nom)
{
    if (!(pdc > 0.0f))
        return 0.0f;
    float zeta = pdc / pdc0;
    float eta = eta_nom / 0.9637f * (-0.0162f * zeta - 0.0059f / zeta + 0.9858f);
    return SS_FMAX(0.0f, SS_FMIN(eta_nom * pdc0, eta * pdc));
}

SS_FN float ss_pv_cell_temp(int model, float poa, float temp_air, float wind)
{
    return model == SS_PV_CELL_TEMP_SAPM ? ss_sapm_cell_temp(poa, temp_air, wind)
                                    : ss_faiman_cell_temp(poa, temp_air, wind);
}

#endif
