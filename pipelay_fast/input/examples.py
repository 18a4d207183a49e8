"""The bundled example cases (``pipelay_fast/examples/*.toml``) and the one
rule that turns a case's name or path into its file.

A bare name (no folder, no ``.toml``), such as ``"s67"``, is a bundled
example; anything else is a path. :func:`pipelay_fast.load_case` and a sweep
file's ``case`` key both resolve through :func:`case_file`. Each example's
first line is a comment describing it in one sentence
(:func:`example_description`), which ``pipelay-fast example`` lists.
"""

from __future__ import annotations

import os
from importlib.resources import files
from pathlib import Path

from .validate import did_you_mean

__all__ = ["case_file", "example_description", "example_names", "example_path",
           "is_bare_name"]


def _folder():
    return files("pipelay_fast").joinpath("examples")


def example_names() -> list[str]:
    """The names of the bundled example cases, sorted."""
    return sorted(p.name.removesuffix(".toml") for p in _folder().iterdir()
                  if p.name.endswith(".toml"))


def example_path(name: str) -> Path:
    """The file of the bundled example ``name``; ValueError, listing the
    examples and suggesting the closest, when there is none of that name."""
    path = _folder().joinpath(f"{name}.toml")
    if is_bare_name(name) and path.is_file():
        return Path(str(path))
    hint, listed = _suggestion(name)
    raise ValueError(f"no bundled example {name!r}{hint}; {listed}")


def _suggestion(name) -> tuple[str, str]:
    """(" (did you mean x?)" or "", "the examples: ...") for an unknown example ``name``."""
    names = example_names()
    return did_you_mean(name, names), f"the examples: {', '.join(names)}"


def example_description(name: str) -> str:
    """The one-line description of the bundled example ``name``: its file's
    first line, a comment, without the ``#``."""
    first = example_path(name).read_text("utf-8").split("\n", 1)[0]
    return first.removeprefix("#").strip()


def is_bare_name(source) -> bool:
    """Whether ``source`` names a bundled example rather than a file: a
    non-empty string without a folder separator or a ``.toml`` ending."""
    return (isinstance(source, str) and bool(source) and "/" not in source
            and os.sep not in source and not source.endswith(".toml"))


def case_file(source: str | os.PathLike, folder: str | os.PathLike | None = None) -> Path:
    """The case file ``source`` names: a bundled example by its bare name
    (:func:`is_bare_name`), unless no example has that name and a file of
    that name exists; else the path, relative to ``folder`` (default: the
    current folder). Raises ValueError for a bare name that is neither, its
    message listing the examples and suggesting the closest; a path is
    returned whether or not it exists."""
    file = Path(folder or ".") / source
    if is_bare_name(source):
        bundled = _folder().joinpath(f"{source}.toml")
        if bundled.is_file():
            return Path(str(bundled))
        if not file.is_file():
            hint, listed = _suggestion(source)
            raise ValueError(f"{source!r} is neither a bundled example nor a file{hint}; "
                             f"{listed} (looked for the file {file})")
    return file
