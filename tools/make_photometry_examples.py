#!/usr/bin/env python3
"""Writes the example photometric files in configs/photometry/ from analytic distributions
(so their exact flux is known and the tests can check the parsers and the flux integral):

  led_bulb_2700k.ies   LM-63-2002, TILT=NONE, rotationally symmetric (one horizontal angle):
                       I(g) = I0 (1 + cos g) / 2, g from nadir 0..180 at 5 deg; flux 2 pi I0.
                       An 806 lm (60 W equivalent) bulb hanging base up.
  led_spot_3000k.ies   LM-63-1995, TILT=INCLUDE (a made-up tilt table), quadrant symmetry
                       (0..90): I(C, g) = I0 cos^4 g (1 + 0.3 cos 2C), g 0..90 at 2.5 deg,
                       C at 15 deg; flux 2 pi I0 / 5 (the cos 2C part integrates to 0). 500 lm.
  led_strip_4000k.ldt  EULUMDAT, Isym 4 (C0..C90 kept of Mc = 24): a Lambertian strip wider
                       across than along, I = I0 cos g (0.8 + 0.2 cos 2C), g 0..90 at 5 deg;
                       flux 0.8 pi I0. Lamp flux 1000 lm, LORL 90 %: 900 lm from the luminaire.

Run from the repository root: python3 tools/make_photometry_examples.py
"""
import math

OUT = "configs/photometry/"


def fmt(v):
    return "%.4f" % v


def wrap(values, per=10):
    return "\n".join(" ".join(values[i:i + per]) for i in range(0, len(values), per))


def ies(path, head, keywords, tilt, lumens, v, h, cd):
    lines = [head] + keywords + [tilt]
    # lamps, lm/lamp, multiplier, n_v, n_h, type C, units m, width, length, height (m)
    lines.append("1 %.1f 1.0 %d %d 1 2 0.06 0.06 0.1" % (lumens, len(v), len(h)))
    lines.append("1.0 1.0 8.5")
    lines.append(wrap([fmt(a) for a in v]))
    lines.append(wrap([fmt(a) for a in h]))
    for plane in cd:
        lines.append(wrap([fmt(c) for c in plane]))
    open(OUT + path, "w").write("\r\n".join(lines) + "\r\n")


# The bulb.
flux = 806.0
i0 = flux / (2 * math.pi)
v = [5.0 * i for i in range(37)]
cd = [[i0 * (1 + math.cos(math.radians(g))) / 2 for g in v]]
ies("led_bulb_2700k.ies", "IESNA:LM-63-2002",
    ["[TEST] lamprig example 1", "[TESTLAB] none: an analytic distribution "
     "(tools/make_photometry_examples.py)", "[MANUFAC] lamprig example",
     "[LUMCAT] LED-BULB-806", "[LUMINAIRE] LED filament bulb, 806 lm, 2700 K, base up",
     "[LAMP] LED 7 W", "[OTHER] I = I0 (1 + cos gamma) / 2, flux 2 pi I0"],
    "TILT=NONE", flux, v, [0.0], cd)

# The spot.
flux = 500.0
i0 = flux * 5 / (2 * math.pi)
v = [2.5 * i for i in range(37)]
h = [15.0 * j for j in range(7)]
cd = [[i0 * math.cos(math.radians(g)) ** 4 * (1 + 0.3 * math.cos(math.radians(2 * c)))
       for g in v] for c in h]
ies("led_spot_3000k.ies", "IESNA:LM-63-1995",
    ["[TEST] lamprig example 2", "[MANUFAC] lamprig example",
     "[LUMINAIRE] LED spot, 500 lm, 3000 K, oval beam",
     "[MORE] I = I0 cos^4 gamma (1 + 0.3 cos 2C), flux 2 pi I0 / 5"],
    "TILT=INCLUDE\r\n1\r\n3\r\n0 45 90\r\n1.0 0.95 0.9", flux, v, h, cd)

# The strip (EULUMDAT).
lamp_flux, lorl = 1000.0, 90.0
i0 = lamp_flux * lorl / 100 / (0.8 * math.pi)
mc, ng = 24, 19
c_angles = [15.0 * j for j in range(mc)]
g_angles = [5.0 * i for i in range(ng)]
kept = c_angles[:mc // 4 + 1]
lines = ["lamprig example (an analytic distribution: tools/make_photometry_examples.py)",
         "2", "4", str(mc), "15", str(ng), "5", "lamprig-example-3",
         "LED strip, 900 lm, 4000 K", "LED-STRIP-900", "led_strip_4000k.ldt", "lamprig",
         "600", "20", "8", "590", "12", "0", "0", "0", "0", "100", fmt(lorl), "1", "0", "1",
         "1", "LED", fmt(lamp_flux), "4000K", "80", "9",
         ] + ["0.5"] * 10
lines += [fmt(c) for c in c_angles] + [fmt(g) for g in g_angles]
for c in kept:
    for g in g_angles:
        # cd per 1000 lm of lamp flux
        lines.append(fmt(i0 * math.cos(math.radians(g)) * (0.8 + 0.2 * math.cos(math.radians(2 * c)))
                         * 1000 / lamp_flux))
open(OUT + "led_strip_4000k.ldt", "w").write("\r\n".join(lines) + "\r\n")
