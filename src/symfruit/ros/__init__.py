"""symfruit on a robot: the ROS 1 and ROS 2 nodes, ROS 2 bags of detections, and their ROS-free core.

- :mod:`.core`: frames in, located fruit out, from any ``sensor_msgs``-shaped messages (no ROS import);
- :mod:`.node`: ``symfruit ros``, the rospy wrapper (Debian's ROS 1 packages; ``make ros-env``);
- :mod:`.node2`: ``symfruit ros2``, the rclpy wrapper (ROS 2 wheels in ``.venv-ros2``; ``make ros2-env``,
  :mod:`.ros2env`), pairing its inputs with :mod:`.sync`; :mod:`.camera2`: a stand-in RealSense camera and a
  listener on ROS 2 (tests, :mod:`.bench2`, trying the node without a camera);
- :mod:`.ros1_msgs`: ``vision_msgs`` classes generated with genpy from the shipped noetic definitions;
- :mod:`.bag2`: ``vision_msgs/msg/Detection3DArray`` into ROS 2 bags with rosbags (extra ``bag``);
- :mod:`.master`: a real ROS master on a free port (tests, benchmark); :mod:`.bench`: node latency;
- :mod:`.debian`: lets the project's venv see Debian's ROS packages.

Nothing here imports ROS at module import time.
"""
