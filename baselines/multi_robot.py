"""The multi-robot experiment of docs/multi-robot.md (heuristic part, and the shared DQN).

    python baselines/multi_robot.py                     # 30 episodes per row (about 1-2 min)
    python baselines/multi_robot.py --episodes 3 --out /tmp/mr   # smoke test
    python baselines/multi_robot.py --episodes 50 \\
        --dqn-30x30 runs/team_30x30 --dqn-rooms64 runs/team_rooms64

Writes to ``baselines/results/multi_robot`` unless ``--out`` says otherwise. The experiment and
its options: :mod:`frontier_marl.experiments.multi_robot`.
"""

from pathlib import Path

from frontier_marl.experiments.multi_robot import main

if __name__ == "__main__":
    raise SystemExit(main(default_out=Path(__file__).resolve().parent / "results" / "multi_robot"))
