"""Training and evaluation of the matching function M (ROS-free).

- ``photo_library``: real photos shipped in packages (scikit-image, Debian darknet), by class;
- ``crop_renderer``: one view of an object's photo region (box jitter, warp, light, blur, noise);
- ``generated_scenes``: scenes with ground-truth identities seen by a moving RGB-D camera;
- ``pair_dataset``: Algorithm 3's percept-anchor pairs, streamed in chunks, class-balanced option;
- ``generated_dataset``: a split of the generated source as a pair set;
- ``embedding_cache``: each crop through the backbone once, persisted as .npz shards;
- ``trainer``: Adam + binary cross entropy, validation per epoch, best checkpoint;
- ``metrics`` / ``pair_scoring`` / ``identity_evaluation`` / ``plots``: the paper's table and
  confusion matrix, anchoring-level identity metrics (motmetrics), PNG figures.

The command-line front ends are ``sailor train`` and ``sailor evaluate``.
"""
