"""The A2C network is the paper's (section V-C): convolutions (kernel, stride) (8, 3), (4, 2),
(3, 1), a 512-unit feature layer, and separate action and value heads."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import torch
from stable_baselines3.common.policies import ActorCriticCnnPolicy
from torch import nn

from davis_ag.benchmark.networks import ARCHITECTURES, PaperCNN

#: Section V-C of the paper.
PAPER_KERNELS_STRIDES = [(8, 3), (4, 2), (3, 1)]
PAPER_FEATURES = 512
#: Section V-C: the input is 224x224 RGB plus the target box channel.
OBSERVATION = gym.spaces.Box(0, 255, (224, 224, 4), dtype=np.uint8)


def policy(arch: str, actions: int = 7) -> ActorCriticCnnPolicy:
    channels_first = gym.spaces.Box(0, 255, (4, 224, 224), dtype=np.uint8)
    return ActorCriticCnnPolicy(channels_first, gym.spaces.Discrete(actions), lambda _: 7e-4, **ARCHITECTURES[arch])


def test_convolutions_are_the_papers() -> None:
    net = PaperCNN(gym.spaces.Box(0, 255, (4, 224, 224), dtype=np.uint8))
    convs = [m for m in net.modules() if isinstance(m, nn.Conv2d)]
    assert [(c.kernel_size[0], c.stride[0]) for c in convs] == PAPER_KERNELS_STRIDES
    assert all(c.kernel_size[0] == c.kernel_size[1] and c.stride[0] == c.stride[1] for c in convs)
    assert convs[0].in_channels == OBSERVATION.shape[2]
    assert all(isinstance(m, nn.ReLU) for m in list(net.cnn)[1:-1:2])


def test_feature_maps_and_feature_vector_sizes() -> None:
    net = PaperCNN(gym.spaces.Box(0, 255, (4, 224, 224), dtype=np.uint8))
    x = torch.zeros(2, 4, 224, 224)
    sizes = []
    for layer in net.cnn:
        x = layer(x)
        if isinstance(layer, nn.Conv2d):
            sizes.append(tuple(x.shape[2:]))
    # floor((224 - 8) / 3) + 1 = 73, floor((73 - 4) / 2) + 1 = 35, 35 - 3 + 1 = 33
    assert sizes == [(73, 73), (35, 35), (33, 33)]
    assert net(torch.zeros(2, 4, 224, 224)).shape == (2, PAPER_FEATURES)
    assert net.features_dim == PAPER_FEATURES


def test_the_policy_has_separate_action_and_value_heads_on_the_papers_features() -> None:
    sb3 = policy("paper", actions=7)
    assert isinstance(sb3.features_extractor, PaperCNN)
    assert sb3.action_net.in_features == PAPER_FEATURES and sb3.action_net.out_features == 7
    assert sb3.value_net.in_features == PAPER_FEATURES and sb3.value_net.out_features == 1
    assert sb3.action_net is not sb3.value_net


def test_natures_first_stride_differs_from_the_papers() -> None:
    """SB3's NatureCNN stays available as an option; it is not the paper's network."""
    nature = policy("nature").features_extractor
    first = next(m for m in nature.modules() if isinstance(m, nn.Conv2d))
    assert (first.kernel_size[0], first.stride[0]) == (8, 4) != PAPER_KERNELS_STRIDES[0]


def test_channels_last_layout_gives_the_same_features_and_loads_either_way() -> None:
    space = gym.spaces.Box(0, 255, (4, 224, 224), dtype=np.uint8)
    torch.manual_seed(0)
    fast = PaperCNN(space)
    plain = PaperCNN(space, channels_last=False)
    plain.load_state_dict(fast.state_dict())
    x = torch.rand(3, 4, 224, 224)
    assert torch.allclose(fast(x), plain(x), atol=1e-5)
    # A checkpoint saved in one layout loads into the other and gives the same features.
    fast.load_state_dict(plain.state_dict())
    assert torch.allclose(fast(x), plain(x), atol=1e-5)
