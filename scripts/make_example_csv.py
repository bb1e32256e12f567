#!/usr/bin/env python3
"""Writes examples/thermal_cycle.csv: one seeded, simulated RLG record of the paper's window.

The chamber cools from 25 C to -40 C at 30 C/h, then heats to +70 C at 10 C/h; recording runs at
1 Hz from the chamber reaching -40 C until it reaches +70 C. The gyro's two sensors lag the air
through a two-node first-order model (housing 20 min, core 60 min), so the gradient grows with
the ramp rate. Bias = B0 + k1*(T - 25) + k0*(T2 - T) + white rate noise (ARW 0.003 deg/sqrt(h));
Earth rate along an up axis at 39.9 N is added and the output is quantized into 1.5" pulses.
True values (for the README): B0 0.05 deg/h, k1 1.2e-3 deg/h/C, k0 0.012 deg/h/C.
"""
import math
import random
import sys

B0, K1, K0 = 0.05, 1.2e-3, 0.012
ARW_DEG_RTH = 0.003
PULSE_ARCSEC = 1.5
EARTH_DPH = 7.292115e-5 * 180 / math.pi * 3600 * math.sin(math.radians(39.9))
TAU_HOUSING_S, TAU_CORE_S = 1200.0, 3600.0


def main(path):
    rng = random.Random(20130301)
    air = housing = core = 25.0
    phase, t_rec, carry = "cool", None, 0.0
    sigma_1s = ARW_DEG_RTH * 60.0  # white rate noise per 1 s sample, deg/h (IEEE 952 C.2)
    with open(path, "w") as f:
        f.write("# simulated RLG, seed 20130301; see scripts/make_example_csv.py\n")
        f.write("time_s,rate_dph,temp_c,temp2_c,air_c\n")
        for _ in range(20 * 3600):
            if phase == "cool":
                air -= 30.0 / 3600
                if air <= -40.0:
                    air, phase, t_rec = -40.0, "heat", 0
            elif phase == "heat":
                air += 10.0 / 3600
            housing += (air - housing) / TAU_HOUSING_S
            core += (housing - core) / TAU_CORE_S
            if t_rec is None:
                continue
            bias = B0 + K1 * (core - 25.0) + K0 * (housing - core) + rng.gauss(0, sigma_1s)
            carry += bias + EARTH_DPH  # 1 deg/h over 1 s = 1 arcsec
            pulses = math.floor(carry / PULSE_ARCSEC)
            carry -= pulses * PULSE_ARCSEC
            f.write(f"{t_rec},{pulses * PULSE_ARCSEC:.1f},{core:.4f},{housing:.4f},{air:.3f}\n")
            t_rec += 1
            if air >= 70.0:
                break


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "examples/thermal_cycle.csv")
