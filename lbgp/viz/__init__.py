"""Visualisation: rerun recordings of episodes, matplotlib figures."""
