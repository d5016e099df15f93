"""Real-data replays: the perceptual and anchoring layers run offline over recorded frames.

``sailor replay SOURCE`` feeds the frames of a source through the same core classes the nodes
use (detector -> ByteTrack -> percept generator -> :class:`~merlin2_sailor.anchoring.anchoring.Anchoring`),
with no ROS, and writes annotated frames, a video and an anchors summary. The sources:

- ``motorcycle`` (:mod:`.motorcycle`): scikit-image's Middlebury stereo frame with metric depth,
  seen by a camera sliding sideways (views synthesised from the real frame and its depth);
- ``sr300`` (:mod:`.sr300`): ViSP's real Intel SR300 RGB-D sequence of a model castle, from
  Debian's ``visp-images-data``, with depth registered to the image and the camera's motion
  estimated by RGB-D visual odometry;
- ``vtest`` (:mod:`.vtest`): OpenCV's pedestrian video from Debian's ``opencv-doc``, monocular,
  with depth from a ground-plane model of the fixed camera.
"""
