"""The ROS side of the behaviours: the ``behaviors`` node that serves each SAILOR action as a
RunPddlAction server, the action-client Behaviour a mission runtime dispatches plan steps with,
and the thin clients (anchoring services, NavigateToPose, Grasp) the state machines talk through.

Everything here is handed a node (or makes its own private one); the state machines themselves
stay ROS-free in :mod:`merlin2_sailor_behaviors.navigation`, ``find_object`` and ``manipulation``.
"""
