#!/usr/bin/env python3
"""An independent check of drop.in: LIGGGHTS's viscoelastic Hertz (normal_model_hertz.h with
limitForce on) for one apple on a rigid-ish steel plate, integrated on its own (semi-implicit
Euler, dt 1e-7) from the touch at v0:

  F = max(0, 4/3 E* sqrt(R u) u + 2 sqrt(5/6) (-beta) sqrt(2 E* sqrt(R u) m) du/dt),
  beta = ln e / sqrt(ln^2 e + pi^2), m* = m (the wall), R* = R,
  1/E* = (1 - 0.18^2)/2.6e6 + (1 - 0.3^2)/2e11.

Prints the peak force, the time the force is > 0, the time the overlap is > 0, and the
restitution at the force's end and at separation, for the eight drops of liggghts.py.
usage: ode_drop.py
"""
import math

R = 0.04
M = 800 * 4 / 3 * math.pi * R ** 3
Y = 1 / ((1 - 0.18 ** 2) / 2.6e6 + (1 - 0.3 ** 2) / 2e11)


def drop(v0, e, g, dt=1e-7):
    b = math.log(e) / math.sqrt(math.log(e) ** 2 + math.pi ** 2)
    u, v, t = 0.0, v0, 0.0  # overlap, its rate (> 0 approaching), time since the touch
    peak, t_f, v_f, started = 0.0, None, None, False
    while True:
        f = 0.0
        if u > 0:
            kn = 4 / 3 * Y * math.sqrt(R * u)
            gn = -2 * math.sqrt(5 / 6) * b * math.sqrt(2 * Y * math.sqrt(R * u) * M)
            f = max(kn * u + gn * v, 0.0)
        if f > 0:
            started = True
            peak = max(peak, f)
        if started and f == 0 and t_f is None:
            t_f, v_f = t, v
        if started and u <= 0:
            return peak, t_f, t, -v_f / v0, -v / v0
        v += (-f + M * g) / M * dt
        u += v * dt
        t += dt


if __name__ == "__main__":
    print("v0 m/s, e, g m/s^2: peak N, contact time F > 0 ms, overlap > 0 ms, e at F = 0, e at separation")
    for g in (0.0, 9.81):
        for e in (0.3, 0.65):
            for v0 in (1.0, 0.5):
                p, tf, to, ef, es = drop(v0, e, g)
                print(f"{v0:g}, {e:g}, {g:g}: {p:.3f} N, {tf * 1e3:.4f} ms, {to * 1e3:.4f} ms, {ef:.4f}, {es:.4f}")
