"""A class decorator giving a plugin the scikit-learn ``__init__`` its ``Config`` implies.

``@stores_config`` writes a keyword-only ``__init__`` whose keywords are exactly the fields of
``cls.Config`` (defaults included, visible to ``inspect.signature``) and which only stores
them, so a plugin with many settings does not repeat each field three times.
"""
from __future__ import annotations

import copy
import dataclasses
import inspect


def stores_config(cls: type) -> type:
    fields = dataclasses.fields(cls.Config)
    defaults, factories = {}, {}
    for f in fields:
        if f.default is not dataclasses.MISSING:
            defaults[f.name] = f.default
        elif f.default_factory is not dataclasses.MISSING:  # type: ignore[misc]
            factories[f.name] = f.default_factory  # e.g. list: called, never stored itself
    names = [f.name for f in fields]

    def __init__(self, **kwargs):
        unknown = sorted(set(kwargs) - set(names))
        if unknown:
            raise TypeError(f"{cls.__name__}() got unexpected keyword(s) {unknown}; valid: "
                            f"{names}")
        for name in names:
            if name in kwargs:
                value = kwargs[name]
            elif name in factories:
                value = factories[name]()
            elif name in defaults:
                value = copy.deepcopy(defaults[name])
            else:
                raise TypeError(f"{cls.__name__}() missing keyword {name!r}")
            setattr(self, name, value)

    params = [inspect.Parameter("self", inspect.Parameter.POSITIONAL_OR_KEYWORD)]
    for f in fields:
        default = f.default if f.default is not dataclasses.MISSING else (
            inspect.Parameter.empty if f.default_factory is dataclasses.MISSING  # type: ignore[misc]
            else f.default_factory())  # type: ignore[misc]
        params.append(inspect.Parameter(f.name, inspect.Parameter.KEYWORD_ONLY, default=default))
    __init__.__signature__ = inspect.Signature(params)  # type: ignore[attr-defined]
    __init__.__qualname__ = f"{cls.__qualname__}.__init__"
    cls.__init__ = __init__
    return cls
