"""Real-robot deployment (planned): motion-capture pose sources, command sinks, safety stop, MCAP
logs. It will reuse, unchanged, everything between the world state and the (v, w) command:
``lbgp.world``, ``lbgp.sim.observation``, the policy, ``lbgp.control`` and ``lbgp.planner``.
Nothing is implemented here yet."""
