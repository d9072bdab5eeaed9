"""The paper's Fig. 8: per method, the proportions of the 0-5 answers to each question, as
stacked bars ((a) tiredness, (b) ease of operation), each panel saying what its scale's ends
mean, drawn with matplotlib (headless)."""

from pbp_drake.studies.atomic_files import save_figure
from pbp_drake.scenarios import METHOD_NAMES
from pbp_drake.studies.figures import new_figure
from pbp_drake.studies.questionnaire import QUESTIONS, SCALE, scale_text

FIG8 = "fig8_questionnaire.png"


def answer_counts(answers, methods, question):
    """`{method: [count of 0, ..., count of 5]}` of `question` over `answers`."""
    counts = {method: [0] * len(SCALE) for method in methods}
    for by_method in answers.values():
        for method in methods:
            value = by_method.get(method, {}).get(question)
            if value is not None:
                counts[method][value] += 1
    return counts


def plot_questionnaire(answers, methods, path):
    """Writes Fig. 8 to `path`: one panel per question, one bar per method, each answer's
    share of the method's answers, 0 (the worse end, red) to 5 (the better, green), the
    panel's title saying what the ends mean for its question."""
    import matplotlib
    colours = matplotlib.colormaps["RdYlGn"]([i / (len(SCALE) - 1) for i in range(len(SCALE))])
    figure, axes = new_figure(1, len(QUESTIONS), figsize=(10, 1.2 + 0.6 * len(methods)),
                              sharey=True)
    labels = [METHOD_NAMES.get(m, m) for m in methods]
    for panel, (axis, (question, asked)) in enumerate(zip(axes, QUESTIONS.items())):
        counts = answer_counts(answers, methods, question)
        left = [0.0] * len(methods)
        for value in SCALE:
            shares = [counts[m][value] / max(sum(counts[m]), 1) for m in methods]
            axis.barh(labels, shares, left=left, color=colours[value], edgecolor="white",
                      label=f"{value}")
            left = [a + b for a, b in zip(left, shares)]
        axis.set_xlim(0, 1)
        axis.set_xlabel("proportion of answers")
        axis.set_title(f"({'ab'[panel]}) {asked.text}\n{scale_text(question)}")
    axes[0].invert_yaxis()  # the first method on top, as in the tables (the axes share y)
    handles, names = axes[0].get_legend_handles_labels()
    figure.legend(handles, names, ncol=len(SCALE), loc="lower center", frameon=False,
                  title="answer (higher is better)")
    figure.tight_layout(rect=(0, 0.12, 1, 1))  # room for the legend below the panels
    save_figure(figure, path, dpi=120, bbox_inches="tight")
