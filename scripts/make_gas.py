#!/usr/bin/env python3
"""A generated gas of N elastic circles (r = 0.05 m) on a grid in a walled box, random
velocities (seed 7), dt 1/60: the contact-heavy scene of README "Running at scale".

  scripts/make_gas.py N DURATION [SPACING] > gas.toml

The default spacing (0.15 m between centres) gives a 1k-circle gas about 10k contacts
per engine over 4 s."""
import math, random, sys

n = int(sys.argv[1])
duration = float(sys.argv[2])
spacing = float(sys.argv[3]) if len(sys.argv) > 3 else 0.15
side = math.ceil(math.sqrt(n))
half = side * spacing / 2 + 0.1
rng = random.Random(7)
out = [f'name = "gas_{n}"', 'dt = 0.0166666666666666667', f'duration = {duration}', '[core]', 'broadphase = "grid"']
walls = [(-half, -half, -half, half), (half, -half, half, half), (-half, -half, half, -half), (-half, half, half, half)]
for k, (x0, y0, x1, y1) in enumerate(walls):
    out += ['[[walls]]', f'name = "w{k}"', f'from = [{x0:.9g}, {y0:.9g}]', f'to = [{x1:.9g}, {y1:.9g}]']
for i in range(n):
    x = (i % side) * spacing - half + 0.1 + spacing / 2
    y = (i // side) * spacing - half + 0.1 + spacing / 2
    vx, vy = rng.uniform(-1, 1), rng.uniform(-1, 1)
    out += ['[[bodies]]', f'name = "c{i}"', 'radius = 0.05', f'position = [{x:.9g}, {y:.9g}]', f'velocity = [{vx:.9g}, {vy:.9g}]']
print("\n".join(out))
