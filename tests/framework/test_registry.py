"""Entry-point discovery, tested with fake entry points (no packages installed)."""
from types import SimpleNamespace

import pytest

import pointatlas
from pointatlas import registry
from pointatlas.errors import PluginError


def fake_ep(name, value, dist="fake-dist", version="1.0"):
    return SimpleNamespace(name=name, value=value, dist=SimpleNamespace(name=dist, version=version))


@pytest.fixture
def fake_group(monkeypatch):
    eps = {}

    def entry_points(group):
        return eps.get(group, [])

    monkeypatch.setattr(registry, "entry_points", entry_points)
    registry.refresh()
    yield eps
    registry.refresh()


def test_load_plugin_returns_class(fake_group):
    fake_group["pointatlas.embedders"] = [fake_ep("good", "pointatlas.errors:ConfigError")]
    assert pointatlas.load_plugin("embedders", "good") is pointatlas.ConfigError
    assert pointatlas.load_plugin("embedder", "good") is pointatlas.ConfigError
    assert pointatlas.load_plugin("pointatlas.embedders", "good") is pointatlas.ConfigError


def test_unknown_name_lists_installed(fake_group):
    fake_group["pointatlas.embedders"] = [fake_ep("alpha", "x:y"), fake_ep("beta", "x:y")]
    with pytest.raises(PluginError, match="No embedder plugin named 'gamma'. Installed: alpha, beta"):
        pointatlas.load_plugin("embedders", "gamma")


def test_unknown_family():
    with pytest.raises(PluginError, match="Valid families"):
        pointatlas.load_plugin("widgets", "x")


def test_duplicate_names_from_two_distributions_is_an_error(fake_group):
    fake_group["pointatlas.sources"] = [
        fake_ep("sphere", "a.mod:Sphere", dist="dist-a"),
        fake_ep("sphere", "b.mod:Sphere", dist="dist-b"),
    ]
    with pytest.raises(PluginError) as err:
        pointatlas.load_plugin("sources", "sphere")
    assert "dist-a" in str(err.value) and "dist-b" in str(err.value)


def test_same_distribution_twice_is_one_plugin(fake_group):
    ep = fake_ep("sphere", "pointatlas.errors:InputError")
    fake_group["pointatlas.sources"] = [ep, ep]
    assert pointatlas.load_plugin("sources", "sphere") is pointatlas.InputError


def test_broken_plugin_warns_and_is_skipped_unless_asked(fake_group):
    fake_group["pointatlas.physics"] = [
        fake_ep("broken", "no_such_module_xyz:Thing"),
        fake_ep("fine", "pointatlas.errors:SchemaError"),
    ]
    with pytest.warns(RuntimeWarning, match="broken"):
        loaded = registry.load_all("physics")
    assert list(loaded) == ["fine"]
    with pytest.raises(PluginError, match="failed to import: ModuleNotFoundError.*Installed physics plugins: broken, fine"):
        pointatlas.load_plugin("physics", "broken")


def test_plugins_lists_name_group_distribution_version_description(fake_group):
    fake_group["pointatlas.studies"] = [fake_ep("s", "pointatlas.errors:ConfigError", "d", "2.0")]
    rows = pointatlas.plugins("study")
    assert rows == [{
        "name": "s", "group": "pointatlas.studies", "distribution": "d", "version": "2.0",
        "description": "A configuration value is missing, misspelt, of the wrong type or out of range.",
    }]


def test_builtin_plugins_are_registered_through_entry_points():
    names = {(row["group"], row["name"]) for row in pointatlas.plugins()}
    assert ("pointatlas.embedders", "isomap") in names
    assert ("pointatlas.sources", "swiss_roll") in names
    assert ("pointatlas.studies", "embedding") in names


def test_every_builtin_plugin_imports():
    """A broken built-in plugin would otherwise only warn and vanish from the lists."""
    broken = [row for row in pointatlas.plugins() if row["distribution"] == "pointatlas"
              and row["description"].startswith("BROKEN")]
    assert broken == []
