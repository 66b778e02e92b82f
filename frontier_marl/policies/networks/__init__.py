"""The torch networks of the learned policies: the SB3 policy classes of the slot scorers
(``slot_dqn``, ``slot_actor_critic``: the ``train`` extra) and the map-aware scorer
(``map_scorer``: torch only)."""
