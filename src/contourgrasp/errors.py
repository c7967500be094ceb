"""The exceptions contourgrasp raises on purpose.

Anything else escaping the library is a bug. The CLI maps these to exit codes:
:class:`InputError` and its subclasses to 2, :class:`NoFeasibleGrasp` to 3.
"""


class InputError(ValueError):
    """Bad input: a file, a field or an argument that cannot be used as given."""


class ContourError(InputError):
    """A contour polygon that cannot be modelled (too few points, NaN, no area, ...)."""


class HandFileError(InputError):
    """A hand description that does not follow the schema."""


class NoFeasibleGrasp(RuntimeError):
    """No pose of the search grid satisfies the constraints; ``reason`` says which one failed."""

    def __init__(self, reason: str):
        super().__init__(reason)
        self.reason = reason


class UnitWarning(UserWarning):
    """Input whose magnitude suggests it is not in SI units."""
