"""Identity in the simulated world, without ROS: tours of a house, generated houses, a training source.

- ``tour``: drive the robot round a house (every waypoint, a look around at each, then back
  through the house) and hand out each frame's percepts as the perceptual layer makes them
  (renderer, ground-truth detector, ByteTrack, percept generator), each with the world object it
  shows;
- ``tour_evaluation``: feed those frames to one :class:`~merlin2_sailor.anchoring.anchoring.Anchoring`
  per matcher, in lockstep, and count what a user counts: duplicate anchors, identity switches;
- ``generated_houses``: random houses (rooms, furniture, objects, photo textures, look-alikes),
  none of them the demo's;
- ``house_source``: the training source made of tours of generated houses, with ground-truth
  identities, for ``sailor train --source houses``.
"""
