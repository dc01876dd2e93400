"""``deploy``: wire a pose source, a policy and a command sink into a DeployLoop and run it."""

from __future__ import annotations

from lbgp.calibration import load_calibration
from lbgp.drive_model import load_drive_model
from lbgp.real.endpoints import open_sink, open_source
from lbgp.real.loop import DeployConfig, DeployLoop


def deploy(policy, source: str = "sim", sink: str | None = None, robot: str = "turtlebot2", steps: int | None = None,
           log=None, record=None, spawn_viewer: bool = False, seed: int = 0, person_path=None, disturbance=None,
           end_distance: float | None = None, metadata: dict | None = None, planner_time_budget: float | None = None,
           first_pose_timeout: float | None = None, on_wait=None, on_open=None, dynamics=None, calibration=None,
           drive_model=None):
    """Run the loop until ``steps`` agent steps (or the source ends, Ctrl-C or a signal); returns the
    loop (metrics in ``loop.metrics``, why it ended in ``loop.end_reason``; an exception raised
    while it ran is in ``loop.error``, after the zero command was sent and the log closed).
    ``calibration``: scales every command sent (``lbgp.calibration``: None, a CommandCalibration or
    ``lbgp sysid``'s JSON). ``drive_model``: the planner's model of the drive (``lbgp.drive_model``:
    None, a named set or ``lbgp sysid``'s JSON)."""
    calibration = load_calibration(calibration, robot)
    drive_model = load_drive_model(drive_model, robot)
    pose_source, world = open_source(source, robot=robot, seed=seed, person_path=person_path, disturbance=disturbance,
                                     dynamics=dynamics)
    if on_open is not None:
        address = getattr(pose_source, "address", None)
        on_open(f"listening for poses on udp://{address[0]}:{address[1]}" if address else f"reading poses from {source}")
    try:
        command_sink = open_sink(sink or ("sim" if world is not None else "none"), world=world)
    except BaseException:
        pose_source.close()
        raise
    logger = recorder = None
    try:
        if log:
            from lbgp.real.mcap_log import McapLogger

            calibrated = {} if calibration.is_identity else {"calibration": calibration.to_dict()}
            if drive_model is not None:
                calibrated["drive_model"] = drive_model.to_dict()
            if getattr(policy, "planner_changes", None):  # the planner the policy was trained on (DeployLoop drives it)
                calibrated["planner_changes"] = dict(policy.planner_changes)
            logger = McapLogger(log, metadata={"robot": robot, "source": source, **calibrated, **(metadata or {})})
        if record or spawn_viewer:
            from lbgp.viz.recording import EpisodeRecorder

            recorder = EpisodeRecorder(record, spawn=spawn_viewer)
        end_condition = (lambda: "contact" if world.contact else None) if world is not None else None
        loop = DeployLoop(pose_source, command_sink, policy, DeployConfig(robot=robot, max_steps=steps, end_distance=end_distance,
                                                                                 planner_time_budget=planner_time_budget,
                                                                                 first_pose_timeout=first_pose_timeout,
                                                                                 calibration=calibration, drive_model=drive_model),
                          logger=logger, recorder=recorder, end_condition=end_condition, on_wait=on_wait)
        loop.error = None
        try:
            loop.run()
        except Exception as exc:  # the loop already sent zero and closed its log; let the caller report
            loop.error = exc
        return loop
    finally:
        if logger is not None:
            logger.close()
        if recorder is not None:
            recorder.close()
        command_sink.close()
        pose_source.close()
