"""The words a person reads about runs, kept in this low layer so that every layer above
(a run's result line, the studies' tables and figures, the console's page) says them the
same way: each method's one name, and a count with its noun in the right number."""

import collections.abc

from pbp_drake.core.methods import METHODS


class _MethodNames(collections.abc.Mapping):
    """Method name -> the name a person reads (`Method.label`), read live from the methods
    registry, so a method registered later has its name here too."""

    def __getitem__(self, name):
        return METHODS[name].label

    def __iter__(self):
        return iter(METHODS)

    def __len__(self):
        return len(METHODS)


#: The name a person reads for each method: on the page's Start button and title, in the
#: results tables and in the figures (`pbp_drake.core.methods.Method.label`).
METHOD_NAMES = _MethodNames()


def counted(count, noun, plural=None):
    """`count` and its noun, singular for exactly one: `counted(1, "trial")` is "1 trial",
    `counted(2, "trial")` "2 trials", `counted(1, "target switch", "target switches")`
    "1 target switch" (`plural` for a noun that does not just add an s)."""
    return f"{count} {noun if count == 1 else plural or noun + 's'}"
