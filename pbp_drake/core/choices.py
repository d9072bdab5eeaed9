"""A name that must be one of a registry's: the message that refuses another, naming the
choices as words and the nearest one."""

import difflib


def did_you_mean(name, choices):
    """` (did you mean 'x'?)` when one of `choices` is close to `name`, else ``."""
    matches = difflib.get_close_matches(str(name), list(choices), n=1)
    return f" (did you mean {matches[0]!r}?)" if matches else ""


def unknown_choice(what, name, choices):
    """"WHAT 'name' is unknown; choose one of a, b, c (did you mean 'b'?)": the message
    that refuses `name`, not one of `choices` (names, or a mapping's keys)."""
    return (f"{what} {name!r} is unknown; choose one of {', '.join(map(str, choices))}"
            f"{did_you_mean(name, choices)}")
