"""What hand and planner files share: presets shipped with the package, files named by path, TOML parsing."""

from __future__ import annotations

import tomllib
from importlib import resources
from pathlib import Path

from ..validation import shown


def preset_names(folder: str) -> list[str]:
    """Names of the ``*.toml`` presets in the package folder ``folder``, sorted."""
    directory = resources.files("contourgrasp").joinpath(folder)
    return sorted(p.name.removesuffix(".toml") for p in directory.iterdir() if p.name.endswith(".toml"))


def read_spec(spec: str, folder: str, *, kind: str, error: type[Exception]) -> tuple[str, str]:
    """The text of preset ``spec`` of ``folder`` or of the file at path ``spec``, and its name for errors.

    Raises ``error`` for a name that is neither a preset nor a file, or a file that cannot be read.
    """
    names = preset_names(folder)
    if spec in names:
        return resources.files("contourgrasp").joinpath(f"{folder}/{spec}.toml").read_text(encoding="utf-8"), \
            f"{kind} preset {spec}"
    path = Path(spec)
    try:
        missing = not path.exists()
    except OSError:  # a name too long to be a path: no file
        missing = True
    if not path.suffix and missing:
        raise error(f"unknown {kind} {shown(spec)}: not a preset ({', '.join(names)}) nor a file")
    try:
        return path.read_text(encoding="utf-8"), str(path)
    except UnicodeDecodeError as err:
        raise error(f"{path}: cannot read {kind} file (not UTF-8 text: byte {err.start} is 0x{err.object[err.start]:02x})") from None
    except OSError as err:
        raise error(f"{shown(str(path))}: cannot read {kind} file ({err.strerror or err})") from None


def flag_or_word(value, words: tuple[str, ...]):
    """``value``, a TOML boolean or one of ``words``; else a ValueError naming every value it may take.

    For a schema's ``bool | Literal[...]`` field, whose union would name only the first type it tried (a boolean).

    >>> flag_or_word("sometimes", ("unbalanced", "hand"))
    Traceback (most recent call last):
    ...
    ValueError: must be true, false, "unbalanced" or "hand", got 'sometimes'
    """
    if not isinstance(value, bool) and value not in words:
        allowed = ", ".join(["true", "false", *(f'"{w}"' for w in words[:-1])]) + f' or "{words[-1]}"'
        raise ValueError(f"must be {allowed}, got {value!r}")
    return value


def parse_toml(text: str, source: str, *, error: type[Exception]) -> dict:
    """The TOML document ``text``; ``error`` names ``source`` when it is not valid TOML.

    A document nested too deeply for the parser (it recurses) is refused as invalid.
    """
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as err:
        raise error(f"{source}: not valid TOML ({err})") from None
    except RecursionError:
        raise error(f"{source}: not valid TOML (arrays or tables nested too deeply)") from None
