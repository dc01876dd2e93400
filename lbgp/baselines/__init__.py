"""Baselines of the paper: HC (EKF person prediction + goal ahead + the same planner)."""
