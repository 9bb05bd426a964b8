"""Every compiled robot model: symoro.models.<robot>.<model>.

<model> is 'full' (the robot's full model) or one of the variants its robot.yaml lists; the
robot itself behaves as its full model (symoro.models.planar2r.regressor(...)).
"""

from . import _symoro


class Robot:
    """A compiled robot: its models as attributes, the full model first."""

    def __init__(self, name, models):
        self.name = name
        self.models = dict(models)  # model name -> Model

    def __getattr__(self, attr):
        models = self.__dict__.get("models", {})
        if attr in models:
            return models[attr]
        if "full" in models and not attr.startswith("_") and hasattr(models["full"], attr):
            return getattr(models["full"], attr)
        raise AttributeError(f"robot '{self.__dict__.get('name')}' has no model '{attr}' (it has: {', '.join(models)})")

    def __dir__(self):
        return sorted(set(super().__dir__()) | set(self.models))

    def __repr__(self):
        return f"<symoro robot {self.name}: models {', '.join(self.models)}>"


def load(folder, cache_dir=None):
    """A robot folder's models through its robot library, compiled on first use (seconds) into the
    robot cache ($SYMORO_CACHE_DIR, else ~/.cache/symoro/robots) and loaded: any robot folder, no
    rebuild of the package. Its models as attributes (robot.full, robot.<variant>), the robot itself
    behaving as its full model; robot.identified is robot.yaml's identified model."""
    name, identified, models = _symoro.load_models(str(folder), None if cache_dir is None else str(cache_dir))
    robot = Robot(name, {m.name: m for m in models})
    robot.identified = robot.models[identified]
    return robot


def _robots():
    robots = {}
    for m in _symoro.model_list():
        robots.setdefault(m.robot, {})[m.name] = m
    return {name: Robot(name, models) for name, models in robots.items()}


_ROBOTS = _robots()
names = sorted(_ROBOTS)  # the compiled robots


def __getattr__(name):
    try:
        return _ROBOTS[name]
    except KeyError:
        raise AttributeError(f"no compiled robot '{name}' (compiled: {', '.join(names)})") from None


def __dir__():
    return sorted(list(globals()) + names)
