"""The words a person reads about runs, kept in this low layer so that every layer above
(a run's result line, the studies' tables and figures, the console's page) says them the
same way: each method's one name, and a count with its noun in the right number."""

#: The name a person reads for each method of `schema.METHODS`: on the page's Start button
#: and title, in the results tables and in the figures. The paper's names where it has them;
#: confidence_alpha has none and reads as `--methods` spells it (as the results tables print it);
#: hop and predict_then_assist are the shared-autonomy baselines' names in Javdani et al.'s papers.
METHOD_NAMES = {
    "pbp_alternated": "PBP-Alt",
    "pbp_continuous": "PBP-Cont",
    "fixed_alpha": "Fixed alpha",
    "confidence_alpha": "confidence_alpha",
    "teleop": "Teleop",
    "pbp_no_user": "PBP-NoUser",
    "hop": "HOP",
    "predict_then_assist": "Predict-then-assist",
}


def counted(count, noun, plural=None):
    """`count` and its noun, singular for exactly one: `counted(1, "trial")` is "1 trial",
    `counted(2, "trial")` "2 trials", `counted(1, "target switch", "target switches")`
    "1 target switch" (`plural` for a noun that does not just add an s)."""
    return f"{count} {noun if count == 1 else plural or noun + 's'}"
