"""Every error a public call raises is an :class:`MmtrackError`.

The library's own errors are ``MmtrackError`` with the CLI's one line. An
argument Python or numpy cannot convert (a string array where numbers are
expected, a negative ``threads``, an unknown keyword) raises
:class:`MmtrackTypeError` or :class:`MmtrackValueError`: ``MmtrackError``
subclasses that are also ``TypeError`` / ``ValueError``, so code catching
either keeps working.
"""

from __future__ import annotations

import functools
from typing import Any, Callable, TypeVar

from ._native import MmtrackError


class MmtrackTypeError(MmtrackError, TypeError):
    """An argument of the wrong type (also a ``TypeError``)."""


class MmtrackValueError(MmtrackError, ValueError):
    """An argument whose value cannot be converted (also a ``ValueError``)."""


F = TypeVar("F", bound=Callable[..., Any])


def raises_mmtrack_errors(function: F) -> F:
    """`function`, raising its TypeError / ValueError / OverflowError as the
    MmtrackError subclasses above, the message prefixed with its name."""

    @functools.wraps(function)
    def call(*args: Any, **kwargs: Any) -> Any:
        try:
            return function(*args, **kwargs)
        except MmtrackError:
            raise
        except TypeError as error:
            raise MmtrackTypeError(f"{function.__name__}: {error}") from error
        except (ValueError, OverflowError) as error:
            # An integer the native call cannot take names no argument
            # ("can't convert negative int to unsigned"): name the keywords
            # that hold a negative or oversized integer.
            suspects = [
                f"{name}={value}"
                for name, value in kwargs.items()
                if isinstance(value, int) and not isinstance(value, bool) and not 0 <= value < 2**63
            ]
            hint = f" ({', '.join(suspects)}: expected a non-negative integer)" if suspects else ""
            raise MmtrackValueError(f"{function.__name__}: {error}{hint}") from error

    return call  # type: ignore[return-value]
