/* Quality factor of a resonance against the structure temperature (host plant, double
 * precision). One law for both modes, chosen by plant.q_temp_law; Q(T0) is the
 * configured q_drive / q_sense, and the law gives Q(T) = Q(T0) qlaw_factor(T).
 *
 * QLAW_CONST (0): Q independent of temperature (the plant before these laws, mech.h:
 *   every damping term scales with wn, so c/m = wn/Q keeps its Q).
 *
 * QLAW_GAS (1), air package: viscous gas damping. In the continuum regime both squeeze-
 *   and slide-film damping coefficients are proportional to the gas's dynamic viscosity
 *   mu (Bao & Yang, "Squeeze film air damping in MEMS", Sens. Actuators A 136 (2007) 3,
 *   eqs. for the squeeze number and Couette flow: c ~ mu), and mu does not depend on the
 *   pressure. Viscosity by Sutherland's law (Sutherland, Phil. Mag. 36 (1893) 507), in
 *   the form and constants of the U.S. Standard Atmosphere 1976 (NOAA/NASA/USAF), eq. (51):
 *       mu(T) = beta T^(3/2) / (T + S),   S = 110.4 K for air,
 *   within 2 % of measured air viscosity from 170 to 1900 K (F. M. White, Viscous Fluid
 *   Flow, 3rd ed., 2006, §1-3.4, table 1-2); Sutherland rather than the power law
 *   mu ~ T^0.7, which is the same law's local slope near 300 K (d ln mu / d ln T =
 *   3/2 - T/(T + S) = 0.77 at 298 K). With c ~ mu and Q = m wn / c:
 *       Q(T) / Q(T0) = [wn(T) / wn(T0)] [mu(T0) / mu(T)]      (-0.26 %/K at 25 degC)
 *   The rarefaction correction of the slip regime (effective viscosity, Veijola et al.,
 *   Sens. Actuators A 48 (1995) 239) depends on the gap and pressure and is not modelled:
 *   at atmospheric pressure and gaps of a few microns it changes the slope little.
 *
 * QLAW_TED (2), vacuum package: thermoelastic damping of silicon flexures (Zener, Phys.
 *   Rev. 52 (1937) 230; Lifshitz & Roukes, Phys. Rev. B 61 (2000) 5600), which limits the
 *   Q of many vacuum-packaged silicon resonators and sets their temperature dependence
 *   (Kim et al., "Temperature dependence of quality factor in MEMS resonators", J.
 *   Microelectromech. Syst. 17 (2008) 755). Zener: Q^-1 = Delta w tau / (1 + (w tau)^2),
 *   Delta = E alpha^2 T / (rho c_p), tau = b^2 rho c_p / (pi^2 kappa) for a flexure of
 *   width b. Far below the thermal relaxation peak (w tau << 1: b = 10 um gives
 *   tau = 0.11 us, w tau = 1e-3 at 1.5 kHz) Q^-1 = E alpha^2 T w b^2 / (pi^2 kappa): rho c_p
 *   cancels, and with E ~ wn^2 (2-29), w = wn:
 *       Q(T) / Q(T0) = [wn(T0) / wn(T)]^3 [kappa(T) / kappa(T0)] [alpha(T0) / alpha(T)]^2 T0 / T
 *   silicon's expansion coefficient by Okada & Tokumaru (J. Appl. Phys. 56 (1984) 314),
 *       alpha(T) = (3.725 (1 - exp(-5.88e-3 (T - 124))) + 5.548e-4 T) 1e-6 /K  (120-1500 K),
 *   its thermal conductivity kappa ~ T^-1.3, which follows Glassbrenner & Slack's data
 *   (Phys. Rev. 134 (1964) A1058) within 3 % from 200 to 500 K. Q then falls about
 *   1.4 %/K at 25 degC (Q(85 degC) / Q(25 degC) = 0.48, Q(-40 degC) / Q(25 degC) = 3.2).
 *   Other vacuum losses (anchor, surface) are weakly temperature dependent; where they
 *   dominate, use QLAW_CONST.
 *
 * Range: each law holds within [QLAW_*_T_MIN_K, QLAW_*_T_MAX_K] of the structure
 * temperature (both include -40..85 degC with margin); outside it the law is held at
 * the edge and *outside is set, which the plant counts as a warning (plant.h). */
#ifndef PLANT_QLAW_H
#define PLANT_QLAW_H

typedef enum { QLAW_CONST = 0, QLAW_GAS = 1, QLAW_TED = 2, QLAW_NLAWS = 3 } qlaw_kind_t;

#define QLAW_GAS_T_MIN_K 170.0
#define QLAW_GAS_T_MAX_K 1900.0
#define QLAW_TED_T_MIN_K 200.0
#define QLAW_TED_T_MAX_K 500.0
#define QLAW_AIR_SUTHERLAND_K 110.4

/* Q(T) / Q(T0) of law (qlaw_kind_t) at the structure temperature temp_k, T0 = temp_ref_k,
 * wn_ratio = wn(T) / wn(T0) of the mode (2-32). Exactly 1 for QLAW_CONST (and for an
 * unknown law). *outside (may be NULL): 1 when temp_k had to be held at the law's edge. */
double qlaw_factor(int law, double temp_k, double temp_ref_k, double wn_ratio, int *outside);

/* The material laws, for tests and reports: air viscosity relative to 298.15 K
 * (Sutherland), silicon's expansion coefficient (1/K, Okada & Tokumaru), silicon's
 * thermal conductivity relative to 300 K (T^-1.3). */
double qlaw_air_viscosity_rel(double temp_k);
double qlaw_si_expansion_per_k(double temp_k);
double qlaw_si_conductivity_rel(double temp_k);

#endif /* PLANT_QLAW_H */
