"""Sensor profiles: what a real RGB-D camera and pose source make of an ideal frame.

``get_profile(name)`` gives a ``SensorProfile`` (ideal, structured-light, tof, stereo);
``degrade_frame`` applies it to one ``Frame``; ``DegradedLog`` / ``degrade_log`` to a whole log.
"""

from hiper_cli.sensor.profiles import PROFILES, SensorProfile, get_profile

__all__ = ["PROFILES", "SensorProfile", "get_profile"]
