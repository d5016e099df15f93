"""Demos: data players, the simulated world and missions, and real-data replays."""
