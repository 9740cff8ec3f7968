"""Wrappers: Gymnasium's own classes when Gymnasium is installed, else equivalents with the same
behaviour (Wrapper, ObservationWrapper, RewardWrapper, ActionWrapper).

The reference's intrinsic-motivation pattern works with either::

    class IntrinsicWrapper(cradle.Wrapper):          # or gymnasium.Wrapper
        def step(self, action):
            obs, reward, terminated, truncated, info = self.env.step(action)
            return obs, reward + self.intrinsic(obs), terminated, truncated, info
"""

from .env import _FallbackEnv, _gymnasium

if _gymnasium is not None:
    Wrapper = _gymnasium.Wrapper
    ObservationWrapper = _gymnasium.ObservationWrapper
    RewardWrapper = _gymnasium.RewardWrapper
    ActionWrapper = _gymnasium.ActionWrapper
else:

    class Wrapper(_FallbackEnv):
        """Wraps an env to change its behaviour; forwards everything it does not override.

        As gymnasium.Wrapper: action_space, observation_space and metadata are the wrapped env's
        unless set on the wrapper; unwrapped is the innermost env. Other public attributes
        (env.model, env.touch, ...) are looked up on the wrapped env.
        """

        def __init__(self, env):
            self.env = env
            self._action_space = None
            self._observation_space = None
            self._metadata = None

        def __getattr__(self, name):
            if name.startswith("_") or name == "env":
                raise AttributeError(f"'{type(self).__name__}' has no attribute '{name}'")
            return getattr(self.env, name)

        def get_wrapper_attr(self, name):
            if name in self.__dict__ or hasattr(type(self), name):
                return getattr(self, name)
            return self.env.get_wrapper_attr(name)

        @property
        def action_space(self):
            return self.env.action_space if self._action_space is None else self._action_space

        @action_space.setter
        def action_space(self, space):
            self._action_space = space

        @property
        def observation_space(self):
            if self._observation_space is None:
                return self.env.observation_space
            return self._observation_space

        @observation_space.setter
        def observation_space(self, space):
            self._observation_space = space

        @property
        def metadata(self):
            return self.env.metadata if self._metadata is None else self._metadata

        @metadata.setter
        def metadata(self, value):
            self._metadata = value

        @property
        def render_mode(self):
            return self.env.render_mode

        @property
        def spec(self):
            return self.env.spec

        @property
        def np_random(self):
            return self.env.np_random

        @np_random.setter
        def np_random(self, value):
            self.env.np_random = value

        @property
        def unwrapped(self):
            return self.env.unwrapped

        def step(self, action):
            return self.env.step(action)

        def reset(self, *, seed=None, options=None):
            return self.env.reset(seed=seed, options=options)

        def render(self):
            return self.env.render()

        def close(self):
            return self.env.close()

        def __str__(self):
            return f"<{type(self).__name__}{self.env}>"

        def __repr__(self):
            return str(self)

    class ObservationWrapper(Wrapper):
        """Transforms observations with self.observation(obs)."""

        def reset(self, *, seed=None, options=None):
            obs, info = self.env.reset(seed=seed, options=options)
            return self.observation(obs), info

        def step(self, action):
            obs, reward, terminated, truncated, info = self.env.step(action)
            return self.observation(obs), reward, terminated, truncated, info

        def observation(self, observation):
            raise NotImplementedError

    class RewardWrapper(Wrapper):
        """Transforms rewards with self.reward(reward)."""

        def step(self, action):
            obs, reward, terminated, truncated, info = self.env.step(action)
            return obs, self.reward(reward), terminated, truncated, info

        def reward(self, reward):
            raise NotImplementedError

    class ActionWrapper(Wrapper):
        """Transforms actions with self.action(action) before the wrapped env sees them."""

        def step(self, action):
            return self.env.step(self.action(action))

        def action(self, action):
            raise NotImplementedError
