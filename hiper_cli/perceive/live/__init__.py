"""Live input: a running ROS 2 robot on rmw_zenoh, read without ROS (``pip install 'hiper[live]'``).

``LiveSource`` reads a robot's topics like a log; ``replay_frames`` publishes a log like a
robot; ``rmw`` holds rmw_zenoh's naming and framing conventions.
"""
