"""Running the project's networks through an inference runtime instead of their training framework.

torch trains the crop backbones and the matching network, and OpenCV DNN can run the SSD detector,
but on a robot's CPU both leave speed on the table: OpenVINO runs the same graphs 2-5 times faster
on two cores and loads without torch. This package is ROS-free and torch-free at import:

- :mod:`.settings`: which runtime, device and thread count a node uses (one dataclass);
- :mod:`.model_cache`: where exported models live, named by a fingerprint of what they came from;
- :mod:`.openvino_runtime`: compiling a model for a device, with the fallback to the CPU;
- :mod:`.export`: turning the project's torch definitions and the shipped TensorFlow graph into
  OpenVINO models (torch is imported there, and only when a torch model is exported).
"""
