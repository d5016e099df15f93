"""The contract between the perceptual and anchoring layers: what one hands the other.

A leaf package (it imports only NumPy and :mod:`merlin2_sailor.errors`), so that
``perception -> contract <- anchoring`` and neither layer imports the other:

- :mod:`.percept`: ``BoundingBox2D`` and ``Percept``, one detected object in the world frame;
- :mod:`.pose`: ``Pose``, a rigid transform (camera and robot poses);
- :mod:`.camera`: ``CameraIntrinsics`` (pinhole model) and the frustum test both layers use.
"""
