/* lamprig — light in a lighting designer's units: colour temperature to the renderer's RGB,
 * candela and lumens to its W/sr.
 *
 * The renderer's colour space. Its three bands are linear sRGB: IEC 61966-2-1 (ITU-R BT.709
 * primaries R 0.64,0.33  G 0.30,0.60  B 0.15,0.06, white D65 0.3127,0.3290). The PNG writer
 * encodes them with the sRGB curve and tags the file sRGB (render/image/png.c), and the
 * calibration compares renders as linear sRGB D65 with Y = 0.2126 R + 0.7152 G + 0.0722 B
 * (calib/compare.h); the material presets' per-band coefficients (configs/materials) are per
 * band of the same space. The XYZ -> RGB matrix here is derived from those primaries, not
 * copied, so its luminance row is the exact one the rounded 0.2126, 0.7152, 0.0722 stand for.
 *
 * The photometric scale. A band value of the renderer is radiometric (W/sr for point and spot
 * intensities, W/(mm^2 sr) for area radiance); its luminous part is K_m Y(rgb) with
 * K_m = 683 lm/W (the SI definition of the candela: 683 lm/W at 540 THz, ~555 nm, where
 * y-bar = 1) and Y the luminance row above. So a light of colour (1, 1, 1) counts its watts as
 * if at 555 nm, and a plain `color` keeps today's meaning. A colour temperature gives the
 * light the colour of a Planckian radiator whose *visible* watts (380-780 nm: the renderer's
 * bands carry no infrared) are the light's `intensity`: its colour is the radiator's RGB
 * scaled so that K_m Y = K(T), the luminous efficacy of that spectrum,
 * K(T) = K_m sum(y-bar B_T) / sum(B_T) over the 5 nm table.
 */
#ifndef LR_PHOTOMETRY_H
#define LR_PHOTOMETRY_H

/* The CIE 1931 2-degree colour-matching functions, 5 nm from 380 to 780 nm (cie1931.c). */
#define LR_CIE_N 81
#define LR_CIE_LAMBDA0_NM 380.0
#define LR_CIE_STEP_NM 5.0
extern const double lr_cie1931_cmf[LR_CIE_N][3];

/* lm/W at 555 nm (540 THz): the definition of the candela. */
#define LR_KM_LM_PER_W 683.0
/* The second radiation constant (m K), the value CIE 015:2004 uses for Planckian radiators
 * (CODATA, ITS-90). Illuminant A was defined with 1.435e-2: see lr_planck_xyz. */
#define LR_PLANCK_C2 1.4388e-2
/* The colour temperatures a light takes (K): the Planckian locus as lamps use it, from a
 * candle's ~1900 K to a clear north sky's ~20000 K. */
#define LR_CCT_MIN_K 1000.0
#define LR_CCT_MAX_K 20000.0

/* XYZ of a Planckian radiator at t_k kelvin (c2 = LR_PLANCK_C2), summed over the 5 nm table
 * (CIE 015's summation), scaled to Y = 1. The spectrum depends on c2 / T only: illuminant
 * A, defined as Planck's law at 2848 K with c2 = 1.435e-2, is t_k = 2848 * 1.4388 / 1.435 =
 * 2855.5 K here (its nominal 2856 K). */
void lr_planck_xyz(double t_k, double xyz[3]);
/* The luminous efficacy (lm/W) of the radiator's power between 380 and 780 nm. */
double lr_planck_efficacy(double t_k);

/* CIE XYZ -> the renderer's linear RGB (above), and RGB's luminance Y. */
void lr_xyz_to_rgb(const double xyz[3], double rgb[3]);
double lr_rgb_luminance(const double rgb[3]);

/* The colour of a light at colour temperature t_k: linear RGB with K_m Y = K(T), i.e. the
 * per-band factor that makes `intensity` the radiator's visible W/sr. May have a slightly
 * negative band outside sRGB's gamut (the locus leaves it below ~1700 K's blue): clipped to
 * 0, then rescaled to keep Y. */
void lr_cct_color(double t_k, double rgb[3]);

/* Exposure as a camera's: EV100, as a reflected-light meter reads it (ISO 2720, calibration
 * constant K = 12.5 cd/m^2). The luminance the meter reads at EV is L(EV) = K 2^EV / 100
 * cd/m^2, and the exposure puts it at 18 % of full scale (mid grey) before the tone curve. A
 * band value in W/(mm^2 sr) has the luminance K_m Y 1e6 cd/m^2, so the renderer's multiplier
 * is exposure = 0.18 K_m 1e6 / L(EV) = 9.8352e8 / 2^EV: EV 0 (0.125 cd/m^2 at mid grey) up
 * to EV 15 (sunlit snow). One EV more halves the image. */
#define LR_METER_K_CD_M2 12.5
#define LR_EV_MID_GREY 0.18
double lr_ev_to_exposure(double ev100);
double lr_exposure_to_ev(double exposure);

/* CIE 1931 xy -> CIE 1960 uv (the space of correlated colour temperature). */
void lr_xy_to_uv1960(double x, double y, double *u, double *v);

#endif
