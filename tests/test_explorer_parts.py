"""The learned explorer's parts: the size-independent slot features, the travel reward, the
masked permutation-equivariant Q-network and the mixed vector env."""

from __future__ import annotations

import numpy as np
import pytest
import torch

import frontier_marl
from frontier_marl import slot_table
from frontier_marl.config import make_config
from frontier_marl.core.slots import SlotArrays, SlotTable
from frontier_marl.policies.base import target_cell
from frontier_marl.sim.features import (
    CELLS,
    EXPLORER_FEATURES,
    UTILITY_RANGE,
    cluster_fill,
    explorer_features,
    log_utility,
    slot_feature_names,
    tour_lengths,
    turn_costs,
    unknown_near,
)
from frontier_marl.sim.motion import TRAIL_STEPS, MotionTrail
from frontier_marl.sim.rewards import StepEvents, step_outcome
from tests.helpers import silent

EXPLORER = {"features": "explorer", "n_slots": 6, "gain": "unknown"}


def _table(targets: list[tuple[int, int]], paths: list[int], n_slots: int = 4) -> SlotTable:
    live = len(targets)
    pad = n_slots - live
    target = np.array(targets + [(-1, -1)] * pad, dtype=np.int64)
    return SlotTable.from_arrays(
        cluster=np.array(list(range(live)) + [-1] * pad),
        valid=np.array([True] * live + [False] * pad),
        centroid=np.where(target >= 0, target, 0).astype(float),
        target=target,
        distance=np.array([float(np.hypot(*t)) for t in targets] + [0.0] * pad),
        size=np.array([3] * live + [0] * pad),
        gain=np.array([10.0] * live + [0.0] * pad),
        path_length=np.array(paths + [-1] * pad),
    )


def test_explorer_features_on_a_hand_made_table() -> None:
    table = _table([(0, 4), (3, 0)], [6, 3])
    heading = np.array([[3, 0]])
    features = explorer_features(SlotArrays.stack([table]), np.array([[0, 0]]), heading)[0]
    column = {name: i for i, name in enumerate(EXPLORER_FEATURES)}
    assert features.shape == (4, len(EXPLORER_FEATURES))
    assert features[:, column["path"]].tolist() == pytest.approx([6 / CELLS, 3 / CELLS, 0, 0])
    assert features[:, column["extra_path"]].tolist() == pytest.approx([3 / CELLS, 0, 0, 0])
    assert features[:, column["isolation"]].tolist() == pytest.approx([5 / CELLS] * 2 + [0, 0])
    assert features[:, column["current"]].tolist() == [0, 1, 0, 0]
    assert features[:, column["live"]].tolist() == [0.5, 0.5, 0, 0]
    assert features[:, column["d_row"]].tolist() == pytest.approx([0, 3 / CELLS, 0, 0])
    assert not features[2:].any()  # padding slots are zeros


def test_tour_lengths_on_a_hand_made_table() -> None:
    line = _table([(0, 0), (0, 3), (0, 10)], [1, 2, 3])
    alone = _table([(5, 5)], [4])
    tours = tour_lengths(SlotArrays.stack([line, alone]))
    assert tours.shape == (2, 4, 1)
    # from (0,0): 3 then 7; from (0,3): back 3 then 10; from (0,10): 7 then 3; padding 0
    assert tours[0, :, 0].tolist() == pytest.approx([10 / CELLS, 13 / CELLS, 10 / CELLS, 0])
    assert not tours[1].any()  # a single live slot has nowhere else to go


def _reference_tour(targets: list[tuple[int, int]], start: int) -> float:
    """The nearest-neighbour tour from ``start`` through ``targets``, the plain way."""
    left, at, total = [i for i in range(len(targets)) if i != start], start, 0.0
    while left:
        gaps = [float(np.hypot(*np.subtract(targets[at], targets[i]))) for i in left]
        at = left[int(np.argmin(gaps))]  # the first of equal gaps: the lower slot
        total += min(gaps)
        left.remove(at)
    return total


@pytest.mark.parametrize("seed", range(20))
def test_tour_lengths_match_the_plain_tour_on_random_tables(seed: int) -> None:
    rng = np.random.default_rng(seed)
    tables, expected = [], []
    for _ in range(5):
        live = int(rng.integers(0, 7))
        targets = [tuple(int(v) for v in rng.integers(0, 6, 2)) for _ in range(live)]  # ties
        tables.append(_table(targets, [1] * live, n_slots=6))
        tours = [_reference_tour(targets, start) / CELLS for start in range(live)]
        expected.append(tours + [0.0] * (6 - live))
    tours = tour_lengths(SlotArrays.stack(tables))[..., 0]
    assert np.allclose(tours, expected, rtol=1e-6)


def test_the_tour_feature_extends_the_explorer_layout_and_needs_it() -> None:
    env = frontier_marl.parallel_env(**EXPLORER, tour=True)
    observations, _ = env.reset(seed=3)
    slots = observations["robot_0"]["observation"]
    assert slots.shape == (6, len(EXPLORER_FEATURES) + 1)
    without = frontier_marl.parallel_env(**EXPLORER).reset(seed=3)[0]["robot_0"]["observation"]
    assert np.array_equal(slots[:, :-1], without)
    with pytest.raises(ValueError, match="tour=True needs features='explorer'"):
        make_config("thesis-20x20", tour=True)


def test_turn_costs_on_a_hand_made_table() -> None:
    table = _table([(5, 9), (5, 1), (9, 5), (5, 5)], [4, 4, 4, 0], n_slots=5)
    slots = SlotArrays.stack([table, table])
    positions = np.array([[5, 5], [5, 5]])
    motion = np.array([[0, 3], [0, 0]])  # moving right; standing still
    turns = turn_costs(slots, positions, motion)
    assert turns.shape == (2, 5, 1)
    # ahead, behind, to the side, on the robot's cell, padding
    assert turns[0, :, 0].tolist() == pytest.approx([0.0, 2.0, 1.0, 0.0, 0.0])
    assert not turns[1].any()  # no motion, no turn


def test_the_motion_trail_spans_the_last_steps_of_active_worlds() -> None:
    trail = MotionTrail(2, 1)
    trail.clear(slice(None), np.array([[[0, 0]], [[4, 4]]]))
    path = [(0, 1), (0, 2), (1, 2), (2, 2), (3, 2)]
    position = np.array([[[0, 0]], [[4, 4]]])
    moved = []
    for cell in path:
        trail.push(position, np.array([True, False]))
        position = np.array([[cell], [[4, 4]]])
        moved.append(trail.motion(slice(None), position)[:, 0].tolist())
    # world 0 moves by the cells of its last TRAIL_STEPS (3) steps; world 1 is never pushed
    assert [m[0] for m in moved] == [[0, 1], [0, 2], [1, 2], [2, 1], [3, 0]]
    assert all(m[1] == [0, 0] for m in moved)
    assert TRAIL_STEPS == 3


def test_the_turn_feature_follows_the_robots_own_steps() -> None:
    env = frontier_marl.parallel_env(**EXPLORER, tour=True, turn=True)
    observations, _ = env.reset(seed=4)
    cells = [env.world.positions[0].copy()]
    for _ in range(12):
        obs = observations["robot_0"]
        assert obs["observation"].shape == (6, len(EXPLORER_FEATURES) + 2)
        oldest = cells[max(len(cells) - 1 - TRAIL_STEPS, 0)]
        here = env.world.positions[0]
        table = env.mdp.slot_tables()[0]
        expected = turn_costs(SlotArrays.stack([table]), here[None], (here - oldest)[None])
        assert np.array_equal(obs["observation"][:, -1], expected[0, :, 0])
        observations, *_ = env.step({"robot_0": int(np.flatnonzero(obs["action_mask"])[-1])})
        cells.append(env.world.positions[0].copy())
    with pytest.raises(ValueError, match="turn=True needs features='explorer'"):
        make_config("thesis-20x20", turn=True)


def test_unknown_near_on_a_hand_made_belief() -> None:
    from frontier_marl.core.grid import FREE, UNKNOWN
    from frontier_marl.sim.features import NEAR

    side = 2 * NEAR + 1
    belief = np.full((40, 60), FREE, dtype=np.int8)
    belief[:, 30:] = UNKNOWN  # the right half unknown
    table = _table([(20, 29), (0, 0), (20, 59)], [1, 2, 3], n_slots=4)
    near = unknown_near(SlotArrays.stack([table]), belief[None])
    assert near.shape == (1, 4, 1)
    # (20, 29): columns 30..41 of rows 8..32 unknown; (0, 0): none; (20, 59): the square is
    # cut by the map's right edge, columns 47..59 of rows 8..32; padding 0
    expected = [12 * side / side**2, 0.0, 13 * side / side**2, 0.0]
    assert near[0, :, 0].tolist() == pytest.approx(expected)


def test_unknown_near_reads_each_worlds_shared_belief_for_its_robots() -> None:
    from frontier_marl.core.grid import FREE, UNKNOWN

    first = np.full((30, 30), FREE, dtype=np.int8)
    second = np.full((30, 30), UNKNOWN, dtype=np.int8)
    tables = [_table([(15, 15)], [1], n_slots=2), _table([(0, 0)], [2], n_slots=2)]
    robots = SlotArrays.stack(tables * 2)  # two worlds of two robots, world after world
    shared = unknown_near(robots, np.stack([first, second]))[..., 0]
    alone = unknown_near(robots, np.stack([first, first, second, second]))[..., 0]
    assert np.array_equal(shared, alone)
    assert shared[:2, 0].tolist() == [0.0, 0.0] and shared[2, 0] == 1.0
    with pytest.raises(ValueError, match="3 robots cannot share 2 belief maps"):
        unknown_near(SlotArrays.stack(tables + tables[:1]), np.stack([first, second]))


def test_unknown_tables_match_numpys_summed_area_tables() -> None:
    from frontier_marl.core.grid import UNKNOWN
    from frontier_marl.sim.features import unknown_tables

    for seed in range(5):
        rng = np.random.default_rng(seed)
        beliefs = rng.integers(-1, 2, size=(3, 7 + seed, 11 - seed)).astype(np.int8)
        expected = np.zeros((3, 8 + seed, 12 - seed), dtype=np.int64)
        expected[:, 1:, 1:] = (beliefs == UNKNOWN).cumsum(axis=1).cumsum(axis=2)
        assert np.array_equal(unknown_tables(beliefs), expected)


def test_the_unknown_near_feature_reads_the_shared_belief() -> None:
    env = frontier_marl.parallel_env(**EXPLORER, tour=True, unknown_near=True, n_agents=2)
    observations, _ = env.reset(seed=5)
    for _ in range(8):
        tables = env.mdp.slot_tables()
        for agent, name in enumerate(env.agents):
            slots = observations[name]["observation"]
            assert slots.shape == (6, len(EXPLORER_FEATURES) + 2)
            expected = unknown_near(SlotArrays.stack([tables[agent]]), env.world.belief[None])
            assert np.array_equal(slots[:, -1], expected[0, :, 0])
        actions = {a: int(np.flatnonzero(observations[a]["action_mask"])[0]) for a in env.agents}
        observations, *_ = env.step(actions)
    with pytest.raises(ValueError, match="unknown_near=True needs features='explorer'"):
        make_config("thesis-20x20", unknown_near=True)


def test_cluster_fill_on_a_hand_made_table() -> None:
    table = _table([(0, 4), (3, 0)], [6, 3])  # clusters of 3 cells
    fill = cluster_fill(SlotArrays.stack([table]), max_cluster_cells=12)
    assert fill.shape == (1, 4, 1)
    assert fill[0, :, 0].tolist() == pytest.approx([0.25, 0.25, 0.0, 0.0])


def test_the_fill_feature_is_the_size_over_the_split_size_on_a_finer_grid() -> None:
    env = frontier_marl.parallel_env(
        **EXPLORER, map_generator="rooms", fill=True, height=60, width=60, map_scale=3,
        perception_range=6, max_cluster_cells=14, map_mode="dynamic",
    )  # fmt: skip
    column = slot_feature_names(env.config.observation).index("fill")
    observations, _ = env.reset(seed=0)
    for _ in range(10):
        table = env.mdp.slot_tables()[0]
        slots = observations["robot_0"]["observation"]
        expected = np.where(table.valid, table.size / 14, 0.0)
        assert slots[:, column] == pytest.approx(expected)
        assert (slots[:, column] <= 1).all()
        action = int(np.flatnonzero(observations["robot_0"]["action_mask"])[0])
        observations, *_ = env.step({"robot_0": action})
    with pytest.raises(ValueError, match="fill=True needs features='explorer'"):
        make_config("thesis-20x20", fill=True)


def test_log_utility_on_a_hand_made_table() -> None:
    table = _table([(0, 4), (3, 0)], [6, 3])  # gain 10 on both live slots
    utility = log_utility(SlotArrays.stack([table]), perception_range=24)
    weight = (24 / UTILITY_RANGE) ** 4  # 16
    expected = [weight * np.log(11 / 7), weight * np.log(11 / 4), 0.0, 0.0]
    assert utility.shape == (1, 4, 1)
    assert utility[0, :, 0].tolist() == pytest.approx(expected, rel=1e-6)
    # at r = 3 the same utility weighs (3 / 12) ** 4 = 1 / 256
    coarse = log_utility(SlotArrays.stack([table]), perception_range=3)[0, :, 0]
    assert coarse[:2] == pytest.approx(np.array(expected[:2]) / 16 / 256, rel=1e-6)


def test_the_utility_feature_in_the_observation() -> None:
    env = frontier_marl.parallel_env(**EXPLORER, fill=True, utility=True, perception_range=5)
    names = slot_feature_names(env.config.observation)
    assert names[-2:] == ["fill", "utility"]
    observations, _ = env.reset(seed=3)
    for _ in range(6):
        table = SlotArrays.stack([env.mdp.slot_tables()[0]])
        slots = observations["robot_0"]["observation"]
        assert np.array_equal(slots[:, -1], log_utility(table, 5)[0, :, 0])
        assert np.isfinite(slots).all()
        action = int(np.flatnonzero(observations["robot_0"]["action_mask"])[0])
        observations, *_ = env.step({"robot_0": action})
    with pytest.raises(ValueError, match="utility=True needs features='explorer'"):
        make_config("thesis-20x20", utility=True)


def test_slot_feature_names_follow_the_encoders_columns() -> None:
    kwargs = {"tour": True, "turn": True, "unknown_near": True, "fill": True, "n_agents": 2}
    env = frontier_marl.parallel_env(**EXPLORER, **kwargs, teammates="positions+targets")
    observations, _ = env.reset(seed=6)
    names = slot_feature_names(env.config.observation)
    slots = observations["robot_0"]["observation"]
    assert slots.shape[1] == len(names) == len(EXPLORER_FEATURES) + 7
    table = SlotArrays.stack([env.mdp.slot_tables()[0]])
    expected = unknown_near(table, env.world.belief[None])[0, :, 0]
    assert np.array_equal(slots[:, names.index("unknown_near")], expected)
    fill = cluster_fill(table, env.config.max_cluster_cells)[0, :, 0]
    assert np.array_equal(slots[:, names.index("fill")], fill)
    assert np.array_equal(slots[:, names.index("tour")], tour_lengths(table)[0, :, 0])


def test_team_features_on_a_hand_made_table() -> None:
    from frontier_marl.sim.features import FAR, TEAM_FEATURES, team_features

    table = _table([(0, 4), (3, 0)], [6, 3])
    slots = SlotArrays.stack([table])
    # two teammates: at (0, 0) heading to (3, 0); at (0, 8) heading nowhere
    mates = np.array([[[0, 0, 3, 0], [0, 8, -1, -1]]], dtype=float)
    features = team_features(slots, mates)[0]
    assert features.shape == (4, len(TEAM_FEATURES))
    assert features[:, 0].tolist() == pytest.approx([4 / CELLS, 3 / CELLS, 0, 0])  # nearest
    assert features[:, 1].tolist() == [0, 1, 0, 0]  # a teammate heads to slot 1's target
    assert features[:, 2].tolist() == pytest.approx([5 / CELLS, 0, 0, 0])
    positions_only = team_features(slots, mates[..., :2])[0]
    assert positions_only[:, 1].tolist() == [0, 0, 0, 0]
    assert positions_only[:2, 2].tolist() == [FAR, FAR]  # no teammate target known


def test_team_explorer_observation_does_not_depend_on_the_team_size() -> None:
    kwargs = {**EXPLORER, "teammates": "positions+targets", "preset": "rooms-32"}
    spaces = [frontier_marl.parallel_env(n_agents=k, **kwargs).observation_space("robot_0")
              for k in (2, 4, 8)]  # fmt: skip
    assert spaces[0] == spaces[1] == spaces[2]
    assert spaces[0]["observation"].shape == (6, len(EXPLORER_FEATURES) + 3)
    one = frontier_marl.parallel_env(preset="rooms-32", **EXPLORER).observation_space("robot_0")
    assert one["observation"].shape == (6, len(EXPLORER_FEATURES))  # the one-robot layout is kept


def test_explorer_observation_does_not_depend_on_the_map_size() -> None:
    small = frontier_marl.parallel_env(preset="thesis-20x20", **EXPLORER)
    large = frontier_marl.parallel_env(preset="rooms-32", height=64, width=64, **EXPLORER)
    assert small.observation_space("robot_0") == large.observation_space("robot_0")
    observation, _ = large.reset(seed=3)
    assert small.observation_space("robot_0").contains(observation["robot_0"])


def test_commit_narrows_the_mask_to_the_previous_target_until_progress() -> None:
    from frontier_marl.core.slots import commit_to_previous

    valid = np.array([[True, True, False], [True, True, False], [True, True, False]])
    mask = valid.astype(np.int8)
    target = np.array([[[1, 1], [4, 2], [-1, -1]]] * 3)
    previous = np.array([[4, 2], [4, 2], [7, 7]])  # still offered, offered, gone
    progressed = np.array([False, True, False])
    narrowed = commit_to_previous(mask, target, valid, previous, progressed)
    assert narrowed.tolist() == [[0, 1, 0], [1, 1, 0], [1, 1, 0]]
    kept = commit_to_previous(mask, target, valid, previous, progressed, "until-reached")
    assert kept.tolist() == [[0, 1, 0], [0, 1, 0], [1, 1, 0]]  # progress does not release it


def test_heuristics_take_the_until_reached_rule() -> None:
    from frontier_marl.policies import make_policy

    env = frontier_marl.parallel_env(preset="rooms-32", n_slots=16)
    for name in ("nearest-path", "coordinated-assignment"):
        policy = make_policy(name, commit="until-reached")
        policy.attach(env)
        observations, infos = env.reset(seed=1)
        previous, kept = None, 0
        for _ in range(60):
            actions = policy.act_team(observations, infos)
            observations, _, _, _, infos = env.step(actions)
            info = infos["robot_0"]
            target, table = target_cell(info["target"]), slot_table(info)
            offered = {tuple(cell) for cell in table.target[: table.live].tolist()}
            if previous is not None and previous in offered:
                assert target == previous, f"{name} left an offered target {previous} for {target}"
                kept += 1
            previous = target if tuple(info["position"].tolist()) != target else None
        assert kept >= 5, f"{name}: the commitment was tested on {kept} steps only"


def test_travel_reward_charges_every_cell_walked_and_idle_steps() -> None:
    cfg = make_config(reward="travel", travel_cost=-0.02, cell_reward=0.05).reward
    events = StepEvents([4, 0], [False, False], [False, False], False, False, 3, 0, [1, 0])
    assert step_outcome(cfg, events).rewards.tolist() == pytest.approx([0.18, -0.02])
    with pytest.raises(ValueError, match="cells each robot walked"):
        step_outcome(cfg, StepEvents([1], [False], [False], False, False, 1, 0))


def test_batched_and_single_explorer_observations_agree() -> None:
    kwargs = {**EXPLORER, "preset": "rooms-32", "reward": "travel", "map_mode": "dynamic"}
    vec = frontier_marl.vector_env(2, **kwargs)
    single = frontier_marl.parallel_env(**kwargs)
    observations, infos = vec.reset(seed=4)
    expected, _ = single.reset(seed=4)
    for _ in range(30):
        action = int(infos["action_mask"][0].argmax())
        observations, rewards, *_, infos = vec.step(np.array([action, 0]))
        expected, single_rewards, *_ = single.step({"robot_0": action})
        assert np.array_equal(observations["observation"][0], expected["robot_0"]["observation"])
        assert rewards[0] == single_rewards["robot_0"]


def _slot_model(n_envs: int = 2, attention_heads: int = 0):  # noqa: ANN202
    from frontier_marl.policies.networks.slot_dqn import MaskedDQN, SlotDQNPolicy
    from frontier_marl.training.batched_vec_env import make_batched_vec_env

    torch.set_num_threads(1)
    cfg = make_config("thesis-20x20", reward="travel", **EXPLORER)
    env = make_batched_vec_env({"config": cfg}, n_envs, seed=0)
    model = MaskedDQN(
        SlotDQNPolicy,
        env,
        learning_starts=50,
        buffer_size=500,
        batch_size=16,
        policy_kwargs={"attention_heads": attention_heads},
    )
    return model, env


@pytest.mark.parametrize("attention_heads", [0, 4])
def test_slot_q_network_is_permutation_equivariant_and_masks(attention_heads: int) -> None:
    model, env = _slot_model(attention_heads=attention_heads)
    observation = env.reset()
    observation["action_mask"][:, 0] = 1
    order = np.random.default_rng(0).permutation(observation["slots"].shape[1])
    shuffled = {key: value[:, order] for key, value in observation.items()}
    q_values = model.q_net(model.policy.obs_to_tensor(observation)[0])
    q_shuffled = model.q_net(model.policy.obs_to_tensor(shuffled)[0])
    assert torch.allclose(q_values[:, order], q_shuffled, atol=1e-5)
    masked = torch.as_tensor(observation["action_mask"] == 0)
    assert (q_values[masked] <= -1e8).all() and (q_values[~masked] > -1e8).all()


def test_attention_reaches_the_q_values_and_survives_save_and_load(tmp_path) -> None:
    from frontier_marl.policies.networks.slot_dqn import MaskedDQN

    model, env = _slot_model(attention_heads=4)
    observation = env.reset()
    tensor = model.policy.obs_to_tensor(observation)[0]
    before = model.q_net(tensor)
    model.save(tmp_path / "model.zip")
    loaded = MaskedDQN.load(tmp_path / "model.zip")
    assert loaded.policy.q_net.q_net.attend is not None
    assert torch.allclose(loaded.q_net(tensor), before)
    # a slot's Q-value depends on the other slots' features through attention, not pooling only
    attend = model.q_net.q_net.attend
    with torch.no_grad():
        attend.out_proj.weight.zero_()
        attend.out_proj.bias.zero_()
    assert not torch.allclose(model.q_net(tensor), before)


@pytest.mark.parametrize("heads", [-1, 3, 1.5, True])
def test_bad_attention_heads_are_refused(heads: object) -> None:
    from frontier_marl.policies.networks.slot_dqn import SlotScorer

    with pytest.raises(ValueError, match="attention_heads"):
        SlotScorer(6, 10, [16, 16], torch.nn.ReLU, heads)  # type: ignore[arg-type]


def test_masked_dqn_only_ever_picks_valid_slots() -> None:
    model, env = _slot_model()
    model.exploration_rate = 1.0
    observation = env.reset()
    for _ in range(40):
        for deterministic in (False, True):
            actions, _ = model.predict(observation, deterministic=deterministic)
            assert observation["action_mask"][np.arange(len(actions)), actions].all()
        observation, *_ = env.step(actions)
    # warm-up (random) and epsilon-greedy steps, trained through the target
    silent(model).learn(200)
    buffer = model.replay_buffer
    stored = buffer.observations["action_mask"][: buffer.pos]
    taken = buffer.actions[: buffer.pos, :, 0]
    assert np.take_along_axis(stored, taken[..., None], axis=2).all()


def test_mixed_vec_env_joins_families_of_different_sizes() -> None:
    from frontier_marl.training.batched_vec_env import MixedVecEnv, make_batched_vec_env

    parts = [
        make_batched_vec_env({"config": make_config(preset, **EXPLORER)}, 2, seed=0)
        for preset in ("thesis-20x20", "rooms-32")
    ]
    mixed = MixedVecEnv(parts)
    observation = mixed.reset()
    assert mixed.num_envs == 4 and observation["slots"].shape[0] == 4
    observation, rewards, dones, infos = mixed.step(mixed.action_masks().argmax(axis=1))
    assert rewards.shape == (4,) and len(infos) == 4
    with pytest.raises(ValueError, match="same observation space"):
        MixedVecEnv([parts[0], make_batched_vec_env({"config": make_config()}, 1)])


@pytest.mark.parametrize(
    ("settings", "message"),
    [
        ({"families": ("random-20", "nope")}, "train.families: unknown family 'nope'"),
        ({"families": "rooms-64"}, "train.families must be a list"),
        ({"families": ("rooms-64",), "vec_env": "supersuit"}, "needs train.vec_env"),
        ({"policy": "transformer"}, "train.policy must be one of"),
        ({"vec_env": "ray"}, "train.vec_env must be one of"),
    ],
)
def test_bad_training_settings_are_refused_by_name(settings: dict, message: str) -> None:
    from frontier_marl.training.experiment import TrainSettings

    with pytest.raises(ValueError, match=message):
        TrainSettings(**settings)


def test_the_shipped_explorer_acts_on_every_family_and_a_floor_plan_size(tmp_path) -> None:
    """`explorer` by name: one model for 20x20 to 64x64 (and a 128x128 example map)."""
    import json

    from frontier_marl.cli.main import main
    from frontier_marl.policies.frontier_rule import FRONTIER_RULE_SETTINGS
    from frontier_marl.policies.models import pretrained_model_dir

    meta = json.loads((pretrained_model_dir("explorer") / "model.json").read_text())
    assert meta["format"] == "map-scorer" and meta["env_settings"] == FRONTIER_RULE_SETTINGS
    out = tmp_path / "bench.json"
    argv = ["benchmark", "--policies", "explorer", "--episodes", "1", "--split", "validation"]
    argv += ["--families", "random-20,random-30,rooms-32,rooms-64"]
    assert main([*argv, "--map", "rooms-128", "--json", str(out), "--no-progress"]) == 0
    rows = json.loads(out.read_text())["rows"]
    assert {row["family"] for row in rows} == {
        "random-20", "random-30", "rooms-32", "rooms-64", "map:rooms-128"
    }  # fmt: skip
    assert all(row["success"] == 1 for row in rows)


def test_the_shipped_team_explorer_acts_for_teams_of_2_4_and_8(tmp_path) -> None:
    """`team-explorer` by name: one model, every robot acting from its own observation."""
    import json

    from frontier_marl.cli.main import main

    for agents in (2, 4, 8):
        out = tmp_path / f"bench-{agents}.json"
        argv = ["benchmark", "--policies", "team-explorer", "--episodes", "1", "--split"]
        argv += ["validation", "--families", "random-30,rooms-64", "--agents", str(agents)]
        assert main([*argv, "--json", str(out), "--no-progress"]) == 0
        rows = json.loads(out.read_text())["rows"]
        assert [row["agents"] for row in rows] == [agents, agents]
        assert all(row["success"] == 1 for row in rows)


@pytest.mark.parametrize(
    ("policy_kwargs", "message"),
    [
        ({"scorer": "tree"}, "scorer must be one of"),
        ({"scorer": "linear", "attention_heads": 4}, "needs scorer='mlp'"),
    ],
)
def test_bad_scorer_settings_are_refused(policy_kwargs: dict, message: str) -> None:
    from frontier_marl.policies.networks.slot_dqn import MaskedDQN, SlotDQNPolicy
    from frontier_marl.training.batched_vec_env import make_batched_vec_env

    env = make_batched_vec_env({"config": make_config("thesis-20x20", **EXPLORER)}, 1)
    with pytest.raises(ValueError, match=message):
        MaskedDQN(SlotDQNPolicy, env, buffer_size=10, policy_kwargs=policy_kwargs)
