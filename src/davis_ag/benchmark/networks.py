"""Feature extractors for the A2C agent: the paper's network (section V-C) and a fast one for tests.

Section V-C: "three convolutional layers---(8, 3), (4, 2), and (3, 1), indicating (kernel size,
stride)---followed by a fully-connected layer to produce 512-dimensional feature vectors", with
separate fully-connected action and value heads (SB3's ``CnnPolicy`` adds those). The paper gives
no channel counts or activations; we take NatureCNN's (32, 64, 64 channels, ReLU), whose layout
it otherwise follows except for the first stride (4 in NatureCNN, 3 in the paper).
"""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import torch
from stable_baselines3.common.torch_layers import BaseFeaturesExtractor
from torch import nn

#: (kernel, stride) of the paper's three convolutions, section V-C.
PAPER_CONVOLUTIONS: tuple[tuple[int, int], ...] = ((8, 3), (4, 2), (3, 1))
#: Size of the paper's feature vector, section V-C.
PAPER_FEATURES = 512
#: Output channels of the three convolutions (not in the paper: NatureCNN's).
CHANNELS: tuple[int, ...] = (32, 64, 64)


class PaperCNN(BaseFeaturesExtractor):
    """The network of section V-C: convolutions (8,3), (4,2), (3,1) with ReLU, then 512 features.

    On the 224x224x4 observation the maps are 73x73, 35x35 and 33x33.
    """

    def __init__(
        self, observation_space: gym.spaces.Box, features_dim: int = PAPER_FEATURES, channels_last: bool = True
    ) -> None:
        """Args:
        observation_space: Channels-first image space (SB3 transposes ours to it).
        features_dim: Size of the feature vector (512 in the paper).
        channels_last: Run the convolutions on channels-last (NHWC) tensors. The same
            network and numbers to float rounding; oneDNN's NHWC kernels made an A2C update
            faster on this CPU (docs/performance.md). Off gives the
            plain NCHW layout the measurement compares with.
        """
        super().__init__(observation_space, features_dim)
        layers: list[nn.Module] = []
        channels = observation_space.shape[0]
        for out, (kernel, stride) in zip(CHANNELS, PAPER_CONVOLUTIONS):
            layers += [nn.Conv2d(channels, out, kernel_size=kernel, stride=stride), nn.ReLU()]
            channels = out
        self.cnn = nn.Sequential(*layers, nn.Flatten())
        with torch.no_grad():
            n_flatten = self.cnn(torch.zeros(1, *observation_space.shape)).shape[1]
        self.linear = nn.Sequential(nn.Linear(n_flatten, features_dim), nn.ReLU())
        self.memory_format = torch.channels_last if channels_last else torch.contiguous_format

    def forward(self, observations: torch.Tensor) -> torch.Tensor:
        """Features of a batch of (already 0-1 scaled) observations."""
        # Flatten reads the maps in logical (C, H, W) order whatever the layout, so the linear
        # layer sees the same features either way.
        return self.linear(self.cnn(observations.contiguous(memory_format=self.memory_format)))


class PooledFeatures(BaseFeaturesExtractor):
    """A small feature extractor for quick runs and tests: 8x average pooling, one conv.

    The paper's network costs ~160 M multiply-adds per 224x224 observation; this one well under
    1 M, so a few thousand A2C steps take seconds on a CPU. Not for results.
    """

    def __init__(self, observation_space: gym.spaces.Box, features_dim: int = 64) -> None:
        """Args:
        observation_space: Channels-first image space (SB3 transposes ours).
        features_dim: Size of the feature vector.
        """
        super().__init__(observation_space, features_dim)
        self.cnn = nn.Sequential(
            nn.AvgPool2d(8), nn.Conv2d(observation_space.shape[0], 16, 3, stride=2), nn.ReLU(), nn.Flatten()
        )
        with torch.no_grad():
            n = self.cnn(torch.zeros(1, *observation_space.shape)).shape[1]
        self.head = nn.Sequential(nn.Linear(n, features_dim), nn.ReLU())

    def forward(self, observations: torch.Tensor) -> torch.Tensor:
        """Features of a batch of (already 0-1 scaled) observations."""
        return self.head(self.cnn(observations))


#: Network choices of A2C training: SB3 ``policy_kwargs`` by name.
ARCHITECTURES: dict[str, dict[str, Any]] = {
    # net_arch []: one linear layer each for actions and value on the 512 features, as the paper
    # has it (SB3 would otherwise put two 64-unit layers in front of each head of a custom extractor).
    "paper": {"features_extractor_class": PaperCNN, "net_arch": []},
    # SB3's CnnPolicy default: NatureCNN, convolutions (8,4), (4,2), (3,1), then 512 features.
    "nature": {},
    "pooled": {"features_extractor_class": PooledFeatures},
}
