"""A stand-in for killing a training process, shared by the tests that resume training."""

from __future__ import annotations

from stable_baselines3.common.callbacks import BaseCallback


class KillAfter(BaseCallback):
    """Stops the process's training with an exception after ``at`` steps, as a kill would."""

    def __init__(self, at: int) -> None:
        super().__init__()
        self.at = at

    def _on_step(self) -> bool:
        if self.model.num_timesteps >= self.at:
            raise KeyboardInterrupt
        return True
