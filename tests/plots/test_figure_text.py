"""Issue 30: text from a model is shown literally in every figure; a failed plot writes nothing.

A model named ``$\\frac{1}{$`` made matplotlib parse mathtext in the titles that name the
model, and the figure failed when drawn (``noise --plot``, the spectrum, the trade-off);
``tradeoff --plot p.png -o t.csv`` then left ``t.csv`` behind.
"""

from __future__ import annotations

import io

import pytest
from matplotlib.cbook import is_math_text

import phdesign.plots.noise
from phdesign.cli import main
from phdesign.core.errors import NumericError
from phdesign.io import model_to_toml, read_model
from phdesign.models import load_builtin
from phdesign.numeric.bridge import to_numeric
from phdesign.numeric.spectrum.converged import spectrum
from phdesign.plots import literal

NAME = "$\\frac{1}{$ and $x$"


@pytest.fixture
def model_file(tmp_path):
    text = model_to_toml(load_builtin("wave")).replace('name = "wave"', 'name = "NAME"')
    path = tmp_path / "m.toml"
    path.write_text(text.replace("NAME", NAME.replace("\\", "\\\\")))
    assert read_model(path).name == NAME
    return path


def _titles(fig) -> list[str]:
    titles = [ax.get_title() for ax in fig.axes]
    if fig._suptitle is not None:
        titles.append(fig._suptitle.get_text())
    return [t for t in titles if t]


def _drawn_literally(fig) -> list[str]:
    """Draw ``fig`` and return the titles that name the model (each shown literally)."""
    fig.savefig(io.BytesIO(), format="png")
    named = [t for t in _titles(fig) if literal(NAME) in t]
    assert named, _titles(fig)
    for title in named:
        assert not is_math_text(title)
    return named


def test_literal_text_is_never_mathtext():
    assert not is_math_text(literal(NAME))
    assert is_math_text(NAME)  # what the model's own name would have been


def test_the_spectrum_figure_shows_the_model_name_literally(model_file):
    nm = to_numeric(read_model(model_file))
    report = spectrum(nm, resolution=8)
    _drawn_literally(report.plot())


def test_noise_plot_of_a_mathtext_model_name(model_file, tmp_path, capsys):
    png = tmp_path / "n.png"
    argv = ["noise", str(model_file), "--sensors", "2", "--gain", "1", "--trace", "e1(1)"]
    assert main([*argv, "--resolution", "8", "--plot", str(png)]) == 0
    assert capsys.readouterr().err == ""
    assert png.read_bytes()[:4] == b"\x89PNG"


TRADE = ["--sensors", "2", "--trace", "e1(1)", "--scales", "0.1:10:2"]


def test_tradeoff_plot_of_a_mathtext_model_name_writes_both_files(model_file, tmp_path, capsys):
    png, table = tmp_path / "p.png", tmp_path / "t.csv"
    argv = ["tradeoff", str(model_file), *TRADE, "--csv", "-o", str(table), "--plot", str(png)]
    assert main(argv) == 0
    assert capsys.readouterr().out == ""
    assert png.read_bytes()[:4] == b"\x89PNG"
    assert table.read_text().startswith("l1,scale,spectral_abscissa")
    from phdesign.numeric.noise.tradeoff import tradeoff

    nm = to_numeric(read_model(model_file))
    result = tradeoff(nm, [[0, 1]], scales=[1.0], performance=["e1(1)"])
    _drawn_literally(result.plot())


def test_a_failed_tradeoff_plot_leaves_no_table(model_file, tmp_path, monkeypatch, capsys):
    def failing(*args, **kwargs):
        raise NumericError("the picture failed")

    monkeypatch.setattr(phdesign.plots.noise, "plot_tradeoff", failing)
    png, table = tmp_path / "p.png", tmp_path / "t.csv"
    argv = ["tradeoff", str(model_file), *TRADE, "-o", str(table), "--plot", str(png)]
    assert main(argv) == 2
    assert capsys.readouterr().err == "phdesign: error: the picture failed\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["m.toml"]
