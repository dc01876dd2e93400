"""Real-robot deployment: the simulator's observation, policy and planner between a pose source and
a command sink.

    sources (frames.PoseFrame)      udp.UdpPoseSource, mocap.MocapPoseSource, replay.McapPoseSource,
                                    sim_world.SimPoseSource
    safety                          safety.SafetyMonitor (stale, NaN, jumps, out of order, too close)
    the loop                        loop.DeployLoop (same code as simulation from WorldState on)
    sinks                           udp.UdpCommandSink, ros2.Ros2TwistSink, sim_world.SimCommandSink
    logs                            mcap_log.McapLogger / read_log, replay.replay_log

``lbgp deploy`` and ``lbgp replay`` wire these together (see docs/deploy.md).
"""
