"""The paper's reported numbers, for the tables that put ours beside them.

Simulation (paper Table "simulation metrics"): (D mean, D std, alpha mean deg, alpha std deg,
accumulated reward) per scenario and method.

Real world (paper Tables "straight", "S shape", "U-turn"): the same per path, setting and method;
None where the paper reports "Failed". The paper's tables identify settings by pictures only; we
take the four blocks in the order the text lists the settings (Ahead, Ahead-right, Ahead-left,
Behind; U-turn: Ahead, Ahead-left, Ahead-far-left, Behind). For the straight path that order
contradicts the text in one place (the text says HC wins only "Ahead" and E2E fails "Ahead", but
the block where HC wins has E2E numbers), so the real-world mapping is uncertain.
"""

SIM = {
    "straight_ahead": {"lbgp": (1.53, 0.2, 7.1, 6.7, 28.31), "hc": (1.35, 0.2, -1.1, 1.6, 33.44), "e2e": (1.75, 0.3, 8.9, 7.2, 27.50)},
    "straight_behind": {"lbgp": (1.59, 0.2, 64.3, 62.6, 10.50), "hc": (1.10, 0.2, 86.1, 66.6, 1.30), "e2e": (1.54, 0.5, 91.8, 63.1, -3.13)},
    "turning_ahead": {"lbgp": (1.90, 0.3, -5.7, 10.3, 24.96), "hc": (1.04, 0.2, -12.6, 11.6, 20.20), "e2e": (1.96, 0.3, -7.5, 4.6, 22.44)},
    "turning_behind": {"lbgp": (1.69, 0.3, 81.7, 67.8, 0.40), "hc": (1.07, 0.3, 83.9, 83.4, -5.03), "e2e": (1.62, 0.5, 55.1, 81.1, 0.17)},
    "turning_inside": {"lbgp": (1.72, 0.3, 1.6, 23.6, 23.04), "hc": (0.98, 0.3, 3.6, 24.1, 8.37), "e2e": (2.11, 0.5, -1.5, 18.7, 11.36)},
    "turning_outside": {"lbgp": (1.56, 0.2, -33.1, 19.8, 13.97), "hc": (1.07, 0.2, -22.8, 18.7, 13.68), "e2e": (1.32, 0.2, 56.3, 72.1, 2.53)},
    "trajectory_one": {"lbgp": (1.37, 0.3, 10.4, 15.4, 27.17), "hc": (1.09, 0.3, -8.8, 34.8, 0.91), "e2e": (1.65, 0.2, 22.9, 42.4, 16.60)},
    "trajectory_two": {"lbgp": (1.54, 0.2, -4.7, 62.2, 15.86), "hc": (1.12, 0.4, -57.0, 45.8, -5.83), "e2e": (1.62, 0.2, -1.7, 72.4, 10.99)},
    "trajectory_three": {"lbgp": (1.59, 0.3, 12.6, 81.0, 11.79), "hc": (1.15, 0.4, 6.2, 75.8, -8.02), "e2e": (1.92, 0.3, 11.0, 80.1, 2.15)},
}

REAL = {
    ("straight", "ahead"): {"lbgp": (1.63, 0.4, -8.4, 26.6, 27.42), "hc": (1.24, 0.6, -11.8, 16.4, 26.31), "e2e": None},
    ("straight", "ahead_right"): {"lbgp": (1.24, 0.3, 2.1, 14.5, 40.92), "hc": (1.14, 0.2, 0.5, 3.0, 61.08), "e2e": (1.14, 0.3, -0.1, 10.0, 41.59)},
    ("straight", "ahead_left"): {"lbgp": (1.61, 0.4, 30.2, 34.6, 15.68), "hc": (1.28, 0.7, 16.8, 21.6, 14.24), "e2e": None},
    ("straight", "behind"): {"lbgp": (1.85, 0.3, 34.0, 95.2, -6.79), "hc": (1.73, 0.3, -105.7, 51.0, -15.69), "e2e": None},
    ("s_shape", "ahead"): {"lbgp": (2.09, 0.3, -4.9, 26.7, 2.30), "hc": (1.14, 0.5, -14.2, 78.4, -9.42), "e2e": None},
    ("s_shape", "ahead_right"): {"lbgp": (1.86, 0.4, 16.9, 28.3, 5.15), "hc": (1.04, 0.3, 38.9, 60.3, -6.83), "e2e": (1.41, 0.4, -35.4, 53.0, 3.45)},
    ("s_shape", "ahead_left"): {"lbgp": (1.81, 0.6, 35.8, 33.1, 11.74), "hc": (1.60, 0.8, 65.3, 50.0, -9.29), "e2e": None},
    ("s_shape", "behind"): {"lbgp": (1.30, 0.2, 38.2, 70.9, 7.84), "hc": (1.69, 0.4, 12.2, 151.6, -18.64), "e2e": None},
    ("u_turn", "ahead"): {"lbgp": (1.99, 0.2, -16.8, 18.6, 14.91), "hc": (1.01, 0.5, -55.2, 57.0, -11.33), "e2e": None},
    ("u_turn", "ahead_left"): {"lbgp": (1.34, 0.4, 20.9, 37.8, 18.73), "hc": (1.15, 0.3, -28.7, 98.1, -8.09), "e2e": (1.75, 0.4, 43.3, 26.7, 10.63)},
    ("u_turn", "ahead_far_left"): {"lbgp": (1.91, 0.7, 36.2, 36.3, 16.52), "hc": (1.31, 0.9, -6.1, 43.8, -13.14), "e2e": None},
    ("u_turn", "behind"): {"lbgp": (1.53, 0.3, 44.5, 58.5, 20.03), "hc": (1.12, 0.3, -1.7, 120.3, -11.83), "e2e": (1.82, 0.3, 67.7, 45.4, -7.43)},
}
