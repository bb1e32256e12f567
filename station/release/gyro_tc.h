/* gyro_tc.h: apply a gyro thermal-bias calibration exported by the gyro thermal-calibration
 * station (`station export --format c|json|csv|px4`). Dependency-free C99 (libc only), for the
 * navigation computer; installed as /usr/include/gyro-station/gyro_tc.h.
 *
 * Model (the paper's eq. (3)/(4), README "Releasing and exporting a calibration"):
 *   B(T, gradT) = B0 + k1 dT + k2 dT^2 + k3 dT^3 + k4 dT^4 + k0 gradT,   dT = T - t_ref_c
 * in deg/h; T is the gyro's first temperature sensor, gradT = second sensor - first, deg C.
 * Outside the span the fit saw, T and gradT are clamped to it (PX4's rule for TC_*_TMIN/TMAX,
 * PX4 Devguide "Thermal Calibration and Compensation"): the polynomial is never extrapolated.
 * A term the fit did not have has coefficient 0.
 *
 * Scale factor (issue 36; IEEE Std 647-2006 for ring laser gyros, IEEE Std 952-1997 for
 * fibre-optic gyros: the scale factor and its temperature sensitivity; station README "The
 * acceptance test"): when sf_measured is 1 the block also holds
 *   K(T) = K0 (1 + TC 1e-6 (T - sf_t_ref_c)),  pulses per arc-second,
 * with T clamped to the span of plateau temperatures the rate ladders covered (the bias's rule),
 * and gyro_tc_rate_dph() applies both models: the input rate is the output divided by K(T), and
 * the thermal bias, fitted on rates at the nominal pulse weight w, is put in input units first
 * (gyro_tc_rate_dph's comment). When sf_measured is 0 ("scale factor: not measured") the scale is
 * left alone: gyro_tc_rate_dph() is the rate minus the bias model.
 *
 * The checksum is CRC-32 (ISO-HDLC: reflected polynomial 0xEDB88320, init and final XOR
 * 0xFFFFFFFF; zlib's crc32) over the canonical text gyro_tc_canonical() writes: a consumer
 * recomputes it with gyro_tc_verify() before use and refuses a block that does not match. */
#ifndef GYRO_TC_H
#define GYRO_TC_H

#include <locale.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#ifdef __cplusplus
extern "C" {
#endif

/* The longest canonical text a block may have (the station refuses to export a longer one). */
#define GYRO_TC_CANONICAL_MAX 1024
/* The largest |K(T) w - 1| a scale-factor model may have: a gyro's scale factor lies within a
 * few hundred ppm of its nominal pulse weight w; beyond 1 % the ladder did not measure the gyro
 * (one that did not follow the table). The station refuses such a ladder by the same bound
 * (compensation/scale_factor.hpp, kMaxScaleFactorDeviation; equal by a static_assert). */
#define GYRO_TC_MAX_SF_DEVIATION 0.01

typedef struct gyro_tc_block {
  const char *serial;      /* gyro serial number */
  const char *part_number; /* "" when the fit was judged against no part */
  long long fit_id;        /* the station's fit id */
  int released;            /* 1: the released calibration; 0: exported with --fit, NOT released */
  double t_ref_c;          /* T_ref, deg C */
  double t_min_c, t_max_c; /* temperature span the fit saw, deg C: T is clamped to it */
  double grad_min_c, grad_max_c; /* gradient span the fit saw, deg C: gradT is clamped to it */
  double b0_dph;           /* B0, deg/h */
  double k_dph[4];         /* k1..k4: deg/h/C, deg/h/C^2, deg/h/C^3, deg/h/C^4 */
  double k0_dph_per_c;     /* k0 (gradient), deg/h/C */
  uint32_t crc32;          /* CRC-32 of gyro_tc_canonical() */
  /* gyro_tc/4: the scale-factor model. After crc32, so a block written for an earlier header
   * (its initializer ends at crc32) still compiles, with sf_measured 0 and its text and checksum
   * unchanged (GCC's -Wextra notes the missing initializers; export again to silence it). */
  int sf_measured;               /* 1: the model below is present; 0: not measured */
  double sf_k0_pulse_per_arcsec; /* K0: the scale factor at sf_t_ref_c, pulses per arc-second */
  double sf_tc_ppm_per_c;        /* TC: its temperature coefficient, ppm/C (0: one plateau) */
  double sf_t_ref_c;             /* T_ref of K0, deg C */
  double sf_t_min_c, sf_t_max_c; /* plateau temperatures the ladders covered: T clamped to it */
  double pulse_weight_arcsec;    /* w: the nominal pulse weight the bias model was fitted at */
  double earth_rate_dph;         /* E: the Earth rate along the input axis in those runs */
} gyro_tc_block;

static inline double gyro_tc_clamp(double x, double lo, double hi) {
  return x < lo ? lo : (x > hi ? hi : x);
}

/* Modelled thermal bias at (temp_c, grad_c), deg/h, with both inputs clamped to the span. A NaN
 * input (a failed sensor) gives NaN: the caller decides what a missing temperature means. */
static inline double gyro_tc_bias_dph(const gyro_tc_block *b, double temp_c, double grad_c) {
  const double dt = gyro_tc_clamp(temp_c, b->t_min_c, b->t_max_c) - b->t_ref_c;
  const double g = gyro_tc_clamp(grad_c, b->grad_min_c, b->grad_max_c);
  double dt_n = dt, model = b->b0_dph;
  int i;
  for (i = 0; i < 4; ++i) {
    model += b->k_dph[i] * dt_n;
    dt_n *= dt;
  }
  return model + b->k0_dph_per_c * g;
}

/* Compensated bias: the measured bias (rate minus Earth rate along the input axis, deg/h) minus
 * the modelled thermal bias. */
static inline double gyro_tc_correct(const gyro_tc_block *b, double bias_dph, double temp_c,
                                     double grad_c) {
  return bias_dph - gyro_tc_bias_dph(b, temp_c, grad_c);
}

/* The scale factor K(T) at temp_c, pulses per arc-second, T clamped to [sf_t_min_c, sf_t_max_c];
 * meaningful only when sf_measured is 1. */
static inline double gyro_tc_scale_factor_pulse_per_arcsec(const gyro_tc_block *b, double temp_c) {
  const double dt = gyro_tc_clamp(temp_c, b->sf_t_min_c, b->sf_t_max_c) - b->sf_t_ref_c;
  return b->sf_k0_pulse_per_arcsec * (1.0 + b->sf_tc_ppm_per_c * 1e-6 * dt);
}

/* The corrected input rate, deg/h, from the gyro's output as a rate at the nominal pulse weight:
 * nominal_rate_dph = output pulses per second * pulse_weight_arcsec (arcsec/s is deg/h), the rate
 * the station records and fits the bias on.
 * Without a scale factor: nominal_rate_dph - B(T, gradT).
 * With one, s = K(T) w (the output per input relative to nominal, 1 + its error):
 *   input rate        nominal_rate_dph / s            (= output pulses per second / K(T))
 *   bias, input units (B + E) / s - E                  (the fit saw (E + bias) s - E at rest)
 *   corrected         nominal_rate_dph / s - ((B + E) / s - E) = (nominal_rate_dph - B - E) / s + E
 * so the bias model is not corrected twice for the scale error of the Earth rate it absorbed. */
static inline double gyro_tc_rate_dph(const gyro_tc_block *b, double nominal_rate_dph,
                                      double temp_c, double grad_c) {
  const double bias_dph = gyro_tc_bias_dph(b, temp_c, grad_c);
  double s;
  if (!b->sf_measured) return nominal_rate_dph - bias_dph;
  s = gyro_tc_scale_factor_pulse_per_arcsec(b, temp_c) * b->pulse_weight_arcsec;
  return (nominal_rate_dph - bias_dph - b->earth_rate_dph) / s + b->earth_rate_dph;
}

/* One number as %.17g with '.' as the decimal point whatever the locale (a consumer that set
 * LC_NUMERIC to a decimal-comma locale still reads the same text). */
static inline void gyro_tc_number(char *buf, size_t n, double v) {
  const char *point = localeconv()->decimal_point;
  char *p;
  snprintf(buf, n, "%.17g", v);
  if (point != NULL && point[0] != '\0' && point[0] != '.')
    for (p = buf; *p != '\0'; ++p)
      if (*p == point[0]) *p = '.';
}

/* Appends `s` to the text in buf (size n, length *len) with ';' written as "%3B" and '%' as
 * "%25": a string field then never holds the separator, so the text is injective (a serial
 * "X;part=Y" with part "" and a serial "X" with part "Y;part=" no longer read alike). Returns 0,
 * or -1 when it does not fit. */
static inline int gyro_tc_put_field(char *buf, size_t n, size_t *len, const char *s) {
  for (; *s != '\0'; ++s) {
    const char *esc = *s == ';' ? "%3B" : (*s == '%' ? "%25" : NULL);
    const size_t k = esc != NULL ? 3u : 1u;
    if (*len + k >= n) return -1;
    if (esc != NULL)
      memcpy(buf + *len, esc, 3);
    else
      buf[*len] = *s;
    *len += k;
  }
  buf[*len] = '\0';
  return 0;
}

/* Appends ";KEY=TEXT"; 0, or -1 when it does not fit. */
static inline int gyro_tc_put_number(char *buf, size_t n, size_t *len, const char *key,
                                     const char *num) {
  const int w = snprintf(buf + *len, n - *len, ";%s=%s", key, num);
  if (w < 0 || (size_t)w >= n - *len) return -1;
  *len += (size_t)w;
  return 0;
}

/* The canonical text the checksum covers, written into buf (size n); returns its length, or -1
 * when it does not fit. Numbers as %.17g: a double prints to the same text on every IEEE-754
 * machine with a correctly rounding printf (glibc, musl, newlib). Version 3 escapes ';' and '%'
 * in the serial and the part number (gyro_tc_put_field); a block whose strings hold neither has
 * nothing to escape and its text is version 2's, byte for byte, under version 2's name, so an
 * earlier checksum of such a block still verifies. One of a block whose serial or part holds ';'
 * or '%' (accepted before the station's text rule) does not: version 2 covered the raw text.
 * The station refuses to re-export such a released block rather than ship a checksum that one
 * of the two headers rejects. Version 4 is a block with a scale factor (sf_measured 1): version
 * 3's escaping, and after k0 the fields sf_k0, sf_tc_ppm, sf_t_ref_c, sf_t_min_c, sf_t_max_c,
 * pulse_weight_arcsec, earth_rate_dph; a block without one writes version 2's or 3's text as
 * before, byte for byte. */
static inline int gyro_tc_canonical(const gyro_tc_block *b, char *buf, size_t n) {
  const double v[] = {b->t_ref_c,  b->t_min_c,  b->t_max_c,  b->grad_min_c, b->grad_max_c,
                      b->b0_dph,   b->k_dph[0], b->k_dph[1], b->k_dph[2],   b->k_dph[3],
                      b->k0_dph_per_c};
  static const char *const key[] = {"t_ref_c", "t_min_c", "t_max_c", "grad_min_c", "grad_max_c",
                                    "b0_dph",  "k1",      "k2",      "k3",         "k4",
                                    "k0"};
  const double sf[] = {
      b->sf_k0_pulse_per_arcsec, b->sf_tc_ppm_per_c, b->sf_t_ref_c, b->sf_t_min_c, b->sf_t_max_c,
      b->pulse_weight_arcsec,    b->earth_rate_dph};
  static const char *const sf_key[] = {"sf_k0",         "sf_tc_ppm",  "sf_t_ref_c",
                                       "sf_t_min_c",    "sf_t_max_c", "pulse_weight_arcsec",
                                       "earth_rate_dph"};
  const int escaped = strpbrk(b->serial, ";%") != NULL || strpbrk(b->part_number, ";%") != NULL;
  const char *version = b->sf_measured ? "gyro_tc/4" : (escaped ? "gyro_tc/3" : "gyro_tc/2");
  char num[40];
  size_t len = 0;
  int i, w;
  if (n == 0) return -1;
  buf[0] = '\0';
  if (gyro_tc_put_field(buf, n, &len, version) != 0 ||
      gyro_tc_put_number(buf, n, &len, "serial", "") != 0 ||
      gyro_tc_put_field(buf, n, &len, b->serial) != 0 ||
      gyro_tc_put_number(buf, n, &len, "part", "") != 0 ||
      gyro_tc_put_field(buf, n, &len, b->part_number) != 0)
    return -1;
  w = snprintf(buf + len, n - len, ";fit=%lld;released=%d", b->fit_id, b->released);
  if (w < 0 || (size_t)w >= n - len) return -1;
  len += (size_t)w;
  for (i = 0; i < 11; ++i) {
    gyro_tc_number(num, sizeof num, v[i]);
    if (gyro_tc_put_number(buf, n, &len, key[i], num) != 0) return -1;
  }
  for (i = 0; b->sf_measured && i < 7; ++i) {
    gyro_tc_number(num, sizeof num, sf[i]);
    if (gyro_tc_put_number(buf, n, &len, sf_key[i], num) != 0) return -1;
  }
  return (int)len;
}

/* CRC-32 (ISO-HDLC), bitwise: small rather than fast; a block is checked once at start-up. */
static inline uint32_t gyro_tc_crc32(const char *s, size_t n) {
  uint32_t crc = 0xFFFFFFFFu;
  size_t i;
  int bit;
  for (i = 0; i < n; ++i) {
    crc ^= (uint32_t)(unsigned char)s[i];
    for (bit = 0; bit < 8; ++bit) crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
  }
  return crc ^ 0xFFFFFFFFu;
}

/* 1 when K(T) w is within GYRO_TC_MAX_SF_DEVIATION of 1 (false for NaN). */
static inline int gyro_tc_sf_near_nominal(const gyro_tc_block *b, double temp_c) {
  const double kw = gyro_tc_scale_factor_pulse_per_arcsec(b, temp_c) * b->pulse_weight_arcsec;
  return kw >= 1.0 - GYRO_TC_MAX_SF_DEVIATION && kw <= 1.0 + GYRO_TC_MAX_SF_DEVIATION;
}

/* 1 when a scale-factor model is absent, or present and usable: its span ordered, w finite and
 * > 0, the Earth rate finite, and K(T) w within GYRO_TC_MAX_SF_DEVIATION of 1 over the span (K
 * is linear in T: its ends bound it); else 0. */
static inline int gyro_tc_scale_factor_ok(const gyro_tc_block *b) {
  if (b->sf_measured == 0) return 1;
  return b->sf_measured == 1 && b->sf_t_min_c <= b->sf_t_max_c && b->pulse_weight_arcsec > 0 &&
         b->pulse_weight_arcsec < 1e300 && b->earth_rate_dph == b->earth_rate_dph &&
         b->earth_rate_dph > -1e300 && b->earth_rate_dph < 1e300 &&
         gyro_tc_sf_near_nominal(b, b->sf_t_min_c) && gyro_tc_sf_near_nominal(b, b->sf_t_max_c);
}

/* 1 when the block's checksum matches its contents, its spans are ordered and its scale-factor
 * model (if any) is usable (gyro_tc_scale_factor_ok), else 0. */
static inline int gyro_tc_verify(const gyro_tc_block *b) {
  char text[GYRO_TC_CANONICAL_MAX];
  const int len = gyro_tc_canonical(b, text, sizeof text);
  if (len < 0) return 0;
  if (!(b->t_min_c <= b->t_max_c) || !(b->grad_min_c <= b->grad_max_c)) return 0;
  if (!gyro_tc_scale_factor_ok(b)) return 0;
  return gyro_tc_crc32(text, (size_t)len) == b->crc32;
}

#ifdef __cplusplus
}
#endif

#endif /* GYRO_TC_H */
