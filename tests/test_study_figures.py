"""The studies' shared figure style, layout check, report formatting and evidence counting.

Every study figure of the tests' tiny runs goes through
:func:`randvib.figure_style.save_figure`, whose layout check is an error
in the tests (``filterwarnings`` in pyproject.toml); these tests show the
check itself catches what it must.

Covers :mod:`randvib.figure_style`, the report's Markdown tables
(:mod:`randvib.studies.report`), the numbers they print (:mod:`randvib.formatting`) and
:mod:`randvib.studies.evidence`.
"""

import matplotlib

matplotlib.use("Agg")

import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402
import pytest  # noqa: E402
from study_checks import unclean_tokens  # noqa: E402

from randvib.figure_style import (  # noqa: E402
    FigureLayoutWarning,
    new_figure,
    num_tex,
    panel_letters,
    save_figure,
    text_overlaps,
)
from randvib.formatting import percent, significant  # noqa: E402
from randvib.studies.evidence import independent_count, rescaling_groups  # noqa: E402
from randvib.studies.report import (  # noqa: E402
    markdown_table,
    readable_table,
    verdict_lines,
    write_verdicts,
)


def test_clean_figure_has_no_overlaps_and_is_saved(tmp_path):
    fig, axes = new_figure(1, 2, figsize=(6, 3))
    for ax in axes[0]:
        ax.plot([0, 1], [0, 1])
        ax.set_xlabel("Coulomb friction $F_c$ (mN)")
        ax.set_title("S = 1 (m/s$^2$)$^2$/Hz")
    panel_letters(axes)
    assert [ax.get_title(loc="left") for ax in axes[0]] == ["(a)", "(b)"]
    assert text_overlaps(fig) == []
    assert save_figure(fig, tmp_path / "clean.png").stat().st_size > 0


def test_overlapping_texts_are_found():
    fig, axes = new_figure(2, 1, figsize=(3, 3))
    # a title placed on the lower panel's tick labels, as tight_layout-free figures did
    axes[0, 0].set_title("a long title over the next panel", y=-0.25)
    axes[1, 0].set_title("a long title over the next panel", y=1.0)
    assert text_overlaps(fig)


def test_a_legend_over_data_is_found_and_one_beside_them_is_not(tmp_path):
    """The check that keeps legends off the data (issue 35, item 17): a legend on a line,
    on markers or on error bars is named with what it covers; a legend below the panels,
    or over a reference line in axes coordinates only, is not."""
    from randvib.figure_style import legends_over_data

    x = np.linspace(0.0, 1.0, 50)
    fig, axes = new_figure(1, 1, figsize=(4, 3))
    ax = axes[0, 0]
    ax.plot(x, 1.0 - x, label="falling line")  # through the upper left corner
    ax.legend(loc="upper left")
    assert legends_over_data(fig) == ["legend 'falling line' over 'falling line'"]
    with pytest.warns(FigureLayoutWarning, match="legend over data"):
        save_figure(fig, tmp_path / "covered.png")
    fig, axes = new_figure(1, 1, figsize=(4, 3))
    ax = axes[0, 0]
    ax.errorbar([0.9], [0.9], yerr=[0.05], fmt="o", label="Monte Carlo")
    ax.plot(x, x**4, label="curve")
    ax.set(xlim=(0, 1), ylim=(0, 1))
    ax.axhline(0.95, color="k")  # a reference line in axes coordinates: not data
    ax.legend(loc="upper right")
    assert legends_over_data(fig) == ["legend 'curve, Monte Carlo' over 'Monte Carlo'"]
    ax.get_legend().remove()
    ax.legend(loc="upper left")  # over the axhline only
    assert legends_over_data(fig) == []
    ax.get_legend().remove()
    fig.legend(*ax.get_legend_handles_labels(), loc="outside lower center")
    assert legends_over_data(fig) == []
    assert save_figure(fig, tmp_path / "clean.png").stat().st_size > 0


def test_save_figure_refuses_layout_without_constrained_engine(tmp_path):
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots()
    ax.plot([0, 1])
    with pytest.raises(FigureLayoutWarning, match="no constrained layout"):
        save_figure(fig, tmp_path / "bad.png")
    plt.close(fig)


def test_number_formats_have_no_nan_or_negative_zero():
    assert significant(float("nan"), 4) == "n/a" and significant(None, 4) == "n/a"
    assert significant(-1e-9, 3) == "-1e-09" and significant(-0.0, 4) == "0"
    assert significant(float("inf"), 4) == "∞"
    assert percent(-0.00001) == "0.00 %" and percent(0.0123, sign=True) == "+1.23 %"
    assert num_tex(5e5) == "5 × 10$^{5}$" and num_tex(1e7) == "10$^{7}$" and num_tex(0.5) == "0.5"
    table = markdown_table(pd.DataFrame({"x": [np.nan, -0.00001, 2.5], "y": ["a", "b", "c"]}))
    assert unclean_tokens(table) == {} and "n/a" in table


def test_unclean_tokens_finds_what_an_outside_reader_should_not_see():
    assert set(unclean_tokens("error nan, at -0 and -0.00 %; see issue 6")) == {
        "nan",
        "-0",
        "issue ",
    }
    assert unclean_tokens("1e-05, -0.0048, finance, tissue") == {}


def test_readable_table_gives_units_and_scales():
    raw = pd.DataFrame({"fc": [0.02], "power_electrical": [1.5e-3], "linearisation_consistent": [True],
                        "linearisation_rel_error": [-0.031], "other": [1.0]})  # fmt: skip
    out = readable_table(raw)
    assert list(out.columns) == ["Fc (mN)", "P Monte Carlo (mW)", "Eq. 32 inside the 95 % CI",
                                 "Eq. 32 error (%)", "other"]  # fmt: skip
    assert out.iloc[0, 2] == "yes"
    assert np.allclose(out.iloc[0, [0, 1, 3, 4]].astype(float), [20.0, 1.5, -3.1, 1.0])


def test_rescaled_rows_count_once_and_only_when_the_numbers_rescale():
    # k3 = 0 at S = 1 and 0.25 with Fc scaled by sqrt(S) and power by S: one experiment
    table = pd.DataFrame(
        {
            "psd": [1.0, 0.25, 1.0, 0.25, 0.25],
            "k3": [0.0, 0.0, 5e5, 5e5, 0.0],
            "fc": [0.02, 0.01, 0.02, 0.01, 0.01],
            "power_electrical": [2e-3, 5e-4, 2e-3, 5e-4, 5.001e-4],
        }
    )
    labels = rescaling_groups(table)
    assert labels[0] == labels[1]  # the rescaled pair
    assert len(set(labels[2:4])) == 2  # Duffing rows do not rescale exactly: both count
    assert labels[4] != labels[0]  # same Fc/sqrt(S) but a different power: not a rescaling
    assert independent_count(table) == 4
    assert independent_count(table.drop(columns="power_electrical")) == 5


def test_verdict_lines_show_sentences_then_numbers(tmp_path):
    write_verdicts(tmp_path, {"a": {"n": 3, "x": 0.123456, "rows": [{"k": 1}]}}, ["It holds."])
    lines = verdict_lines(tmp_path)
    assert lines == ["- It holds.", f"  (3 numbers behind them in {tmp_path / 'verdicts.json'})"]
    assert verdict_lines(tmp_path / "missing") == []
    # with sentences, a long word value behind them is counted, not printed as a sentence
    where = "upper bound (the closure's validity limit: u0 = 1.25 sigma_v, of the device)"
    write_verdicts(tmp_path, {"optima": {"S=1": {"where": where}}}, ["It holds."])
    assert verdict_lines(tmp_path) == [
        "- It holds.", f"  (1 number behind them in {tmp_path / 'verdicts.json'})"
    ]  # fmt: skip
    # no sentence stored: the report's verdict paragraphs, else the numbers themselves
    write_verdicts(tmp_path, {"a": {"n": 3}})
    assert verdict_lines(tmp_path) == ["  a.n: 3"]
    (tmp_path / "report.md").write_text("# T\n\n## S\n\nText.\n\n**Verdict.** It holds\nhere.\n")
    assert verdict_lines(tmp_path)[0] == "- It holds here."
    (tmp_path / "report.md").write_text("**Verdict.**\n\n- **a**: one.\n- **b**: two.\n")
    assert verdict_lines(tmp_path) == [
        "- a: one.", "- b: two.", f"  (1 number behind them in {tmp_path / 'verdicts.json'})"
    ]  # fmt: skip


def test_fit_window_holds_about_thirty_cycles():
    """figure_fit's default window: 30 oscillations of the output, at most 2 s."""
    from types import SimpleNamespace

    from randvib.identification.plots import default_window

    t = np.arange(0, 10, 1e-3)
    fast = SimpleNamespace(time=t, z=np.sin(2 * np.pi * 60 * t + 0.3))
    slow = SimpleNamespace(time=t, z=np.sin(2 * np.pi * 5 * t + 0.3))
    assert default_window(fast) == pytest.approx(0.5, rel=0.01)
    assert default_window(slow) == 2.0
