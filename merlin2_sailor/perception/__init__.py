"""The perceptual layer's ROS-free core: from an RGB-D frame and a camera pose to percepts.

detector (backends by name) -> tracker (ByteTrack ids) -> percept generator (crop + 3D box in the
world frame), with the camera model, depth decoding, stamp synchronisation and crop embedding
beside them. Nothing here imports rclpy or message types; heavy dependencies (OpenCV DNN models,
trackers, torch, Ultralytics) are imported by the module that needs them, when it is used.
"""
