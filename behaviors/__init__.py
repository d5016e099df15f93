"""State-machine behaviors (MERLIN2 actions) built on the anchoring and knowledge layers."""
