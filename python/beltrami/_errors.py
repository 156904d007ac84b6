"""The exceptions of beltrami.

Every error of the package is a :class:`BeltramiError`; each kind also derives from the
built-in exception a Python user would catch for it (``ValueError`` for bad input,
``OSError`` for files, ``RuntimeError`` for a solve that failed). Messages are those of
the ``beltrami`` command-line program and name the offending element (vertex, face,
line, option). A solve stopped by Ctrl-C raises ``KeyboardInterrupt``.
"""


class BeltramiError(Exception):
    """Base class of every beltrami error."""


class MeshError(BeltramiError, ValueError):
    """An invalid mesh: arrays of the wrong shape, an index out of range, a non-finite
    coordinate, a degenerate or duplicate face, a non-manifold edge or vertex."""


class MeshFileError(BeltramiError, OSError):
    """A mesh file that cannot be read or written (missing, unreadable, malformed,
    unknown extension)."""


class OptionError(BeltramiError, ValueError):
    """A keyword argument or solver option that is unknown, of the wrong type or out of
    range."""


class ConstraintError(BeltramiError, ValueError):
    """A pin, landmark or boundary map that does not fit the mesh."""


class FieldError(BeltramiError, ValueError):
    """A Beltrami coefficient that is not admissible: ``|mu| >= 1``, not finite, or not
    one value per face."""


class UnsupportedError(BeltramiError, ValueError):
    """A mesh the solver does not take: wrong topology, element type or target."""


class SolverError(BeltramiError, RuntimeError):
    """A solve that failed (a singular system, a map that folds where folds are
    refused)."""


__all__ = [
    "BeltramiError",
    "MeshError",
    "MeshFileError",
    "OptionError",
    "ConstraintError",
    "FieldError",
    "UnsupportedError",
    "SolverError",
]
