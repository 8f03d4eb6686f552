"""Write the synthetic two-plane, four-probe example of docs/balancing.md.

A rig with two disks (planes disk1 and disk2, masses at 0.08 m) and an XY pair of probes
at each bearing (B1X, B1Y, B2X, B2Y, in um), at 1800 and 3000 rpm. The influence
coefficients and the unbalance as found are made up here (seeded), so the answer is
known: the correction that cancels the unbalance is -U = 2.00 g at 225 deg on disk1 and
1.50 g at 60 deg on disk2 (0.08 m). The vectors carry Gaussian noise of 0.3 um on each of
re and im, stated in their std column. Run with the standard library only:

    python3 docs/examples/balance/make_example.py docs/examples/balance
"""

import cmath
import math
import random
import sys

RADIUS = 0.08
SENSORS = ["B1X", "B1Y", "B2X", "B2Y"]
SPEEDS = [1800.0, 3000.0]
PLANES = ["disk1", "disk2"]
SIGMA = 0.3  # um, on each of re and im

# the unbalance as found: the opposite of the correction
U = [-cmath.rect(2.0e-3 * RADIUS, math.radians(225.0)), -cmath.rect(1.5e-3 * RADIUS, math.radians(60.0))]

# calibration runs: (name, [(plane, mass kg, angle deg), ...])
RUNS = [
    ("asfound", [("disk1", 0.0, 0.0), ("disk2", 0.0, 0.0)]),
    ("trial1", [("disk1", 5.0e-3, 30.0)]),
    ("trial2", [("disk2", 5.0e-3, 200.0)]),
    ("trial12", [("disk1", 4.0e-3, 120.0), ("disk2", 4.0e-3, 300.0)]),
]


def influence(rng):
    """H[sensor][speed][plane] in um / (kg m): each disk acts most on its near bearing."""
    h = {}
    for s, name in enumerate(SENSORS):
        for w, speed in enumerate(SPEEDS):
            gain = 2.0e5 * (1.0 + w)  # um per kg m
            row = []
            for p in range(2):
                near = 1.0 if p == s // 2 else 0.4
                row.append(cmath.rect(near * gain * rng.uniform(0.7, 1.3), rng.uniform(0.0, 2.0 * math.pi)))
            h[(name, speed)] = row
    return h


def main(out):
    rng = random.Random(28)
    h = influence(rng)
    noise = random.Random(2028)
    with open(f"{out}/vectors.csv", "w") as f:
        f.write("run,speed_rpm,sensor,re,im,unit,std\n")
        for run, masses in RUNS:
            t = [0j, 0j]
            for plane, m, a in masses:
                t[PLANES.index(plane)] += cmath.rect(m * RADIUS, math.radians(a))
            for name in SENSORS:
                for speed in SPEEDS:
                    row = h[(name, speed)]
                    v = sum(row[p] * (U[p] + t[p]) for p in range(2))
                    v += complex(noise.gauss(0.0, SIGMA), noise.gauss(0.0, SIGMA))
                    f.write(f"{run},{speed:g},{name},{v.real:.4f},{v.imag:.4f},um,{SIGMA}\n")
    with open(f"{out}/masses.csv", "w") as f:
        f.write("run,plane,mass_kg,radius_m,angle_deg\n")
        for run, masses in RUNS:
            for plane, m, a in masses:
                f.write(f"{run},{plane},{m:g},{RADIUS},{a:g}\n")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else ".")
