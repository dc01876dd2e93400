"""ROS 2 command sink: publishes ``geometry_msgs/Twist`` on a topic (default ``/cmd_vel``).
Needs a sourced ROS 2 installation (``rclpy``); the rest of lbgp works without it."""

from __future__ import annotations


class Ros2TwistSink:
    def __init__(self, topic: str = "/cmd_vel", node_name: str = "lbgp_follow_ahead"):
        try:
            import rclpy
            from geometry_msgs.msg import Twist
        except ImportError:
            raise ImportError("the ros2:// command sink needs ROS 2 (rclpy and geometry_msgs); source your ROS 2 setup first") from None
        if not rclpy.ok():
            rclpy.init()
        self._rclpy, self._twist = rclpy, Twist
        self.node = rclpy.create_node(node_name)
        self.publisher = self.node.create_publisher(Twist, topic, 10)

    def send(self, t: float, v: float, w: float, status: str = "ok") -> None:
        msg = self._twist()
        msg.linear.x, msg.angular.z = float(v), float(w)
        self.publisher.publish(msg)

    def close(self) -> None:
        self.node.destroy_node()
