"""The torch networks of the learned policies (SB3 policy classes); need the ``train`` extra."""
