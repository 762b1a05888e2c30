r"""The documentation's formulas render without a network: MathJax ships with the site.

A page with the kinds of formula the site uses (inline, display, AMS environments) is
built with the project's own ``docs/conf.py`` into a temporary folder (one page: about
3 s, against minutes for the whole site) and opened in headless Chromium with every
network request refused (a dead proxy and a host resolver that resolves nothing).  What
is checked is what a reader sees: every formula Sphinx wrote (``<span class="math">``,
``<div class="math">``) holds a typeset MathJax element, and the visible text has no raw
TeX delimiter ``\(`` or ``\[`` and no MathJax error.  The same page with the shipped
MathJax removed shows the raw ``\(`` (so the check can fail, and the rendering comes from
the copy in the site, not from a network or a browser cache).

Needs the docs extra, MathJax 2 (Debian's libjs-mathjax) and Chromium (Debian's chromium);
``.ci/run`` installs both and sets ``PHDESIGN_CI``, under which a missing one fails instead
of skipping.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from html.parser import HTMLParser
from pathlib import Path

import pytest

DOCS = Path(__file__).resolve().parents[1] / "docs"
sys.path.insert(0, str(DOCS / "_ext"))
pytest.importorskip("sphinx", reason="install the docs extra")
offline_math = pytest.importorskip("offline_math")

#: Chromium's flags: headless, no first-run or background traffic, and no network at all.
OFFLINE = (
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--proxy-server=127.0.0.1:9",  # the discard port: every http(s) request fails
    "--host-resolver-rules=MAP * ~NOTFOUND",  # and no name resolves
)
#: Virtual time given to the page's scripts before the DOM is dumped (ms); MathJax 2
#: typesets this page in well under a second.
BUDGET_MS = 20000

PAGE = r"""
Formulas
========

The certificate :math:`\kappa^* = \tfrac12 \lambda_{\min}(L + L^\top)` and the error energy
:math:`\tilde H = \tfrac12 \tilde e^\top E \tilde e`.

.. math::

   \partial_t x = \sum_{k=0}^N P_k \partial_z^k (\mathcal H x)

.. math::
   :nowrap:

   \begin{align}
   E \dot{\hat e} &= (J - R)\hat e + B u, &
   W_B &= \begin{bmatrix} 1 & 0 \\ 0 & \operatorname{diag}(1, 2) \end{bmatrix}
   \end{align}
"""
FORMULAS = 4


def _require(found: object, what: str) -> None:
    """Skip without ``found``, except in CI (``PHDESIGN_CI``), where it must be there."""
    if found:
        return
    if os.environ.get("PHDESIGN_CI"):
        pytest.fail(f"{what} is missing in CI (.ci/run installs it)")
    pytest.skip(f"needs {what}")


def chromium() -> str:
    """Return the Chromium executable (skipped without one, failed in CI)."""
    found = next(filter(None, map(shutil.which, ("chromium", "chromium-browser"))), None)
    _require(found, "Chromium (Debian: apt-get install chromium)")
    return str(found)


@pytest.fixture(scope="module")
def site(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """One page built with the project's conf.py (warnings as errors)."""
    try:
        offline_math.mathjax_folder()
    except offline_math.MathJaxMissing as error:
        _require(None, f"MathJax 2 ({error})")
    root = tmp_path_factory.mktemp("offline-docs")
    (root / "src").mkdir()
    (root / "src" / "index.rst").write_text(PAGE, encoding="utf-8")
    build = subprocess.run(
        [sys.executable, "-m", "sphinx", "-W", "-q", "-E", "-b", "html", "-c", str(DOCS),
         str(root / "src"), str(root / "html")],
        capture_output=True, text=True, check=False,
    )  # fmt: skip
    assert build.returncode == 0, build.stderr
    return root / "html"


class _Visible(HTMLParser):
    """The text a reader sees (no scripts, styles or head), and the typeset formulas."""

    def __init__(self) -> None:
        super().__init__()
        self.text: list[str] = []
        self.hidden = 0
        self.formulas = 0  # <span class="math"> / <div class="math"> written by Sphinx
        self.typeset = 0  # MathJax 2's CommonHTML output, one per formula

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        classes = (dict(attrs).get("class") or "").split()
        if tag in ("script", "style", "head", "title"):
            self.hidden += 1
        if tag in ("span", "div") and "math" in classes:
            self.formulas += 1
        if "MathJax_CHTML" in classes:
            self.typeset += 1

    def handle_endtag(self, tag: str) -> None:
        if tag in ("script", "style", "head", "title"):
            self.hidden -= 1

    def handle_data(self, data: str) -> None:
        if not self.hidden:
            self.text.append(data)


def rendered(page: Path, tmp_path: Path) -> _Visible:
    """Open ``page`` offline in a fresh profile and return what its DOM shows."""
    profile = tmp_path / f"profile-{page.parent.name}"
    run = subprocess.run(
        [chromium(), *OFFLINE, f"--user-data-dir={profile}",
         f"--virtual-time-budget={BUDGET_MS}", "--dump-dom", page.as_uri()],
        capture_output=True, text=True, timeout=120, check=False,
    )  # fmt: skip
    assert run.returncode == 0, run.stderr[-2000:]
    seen = _Visible()
    seen.feed(run.stdout)
    return seen


def test_the_site_loads_mathjax_from_itself(site: Path) -> None:
    html = (site / "index.html").read_text(encoding="utf-8")
    assert 'src="_static/mathjax/MathJax.js?config=TeX-AMS_CHTML"' in html
    assert "cdn" not in html.lower()
    assert (site / "_static" / "mathjax" / "MathJax.js").is_file()


def test_formulas_render_offline_in_headless_chromium(site: Path, tmp_path: Path) -> None:
    seen = rendered(site / "index.html", tmp_path)
    text = "".join(seen.text)
    assert seen.formulas == FORMULAS, text
    assert seen.typeset == FORMULAS, f"{seen.typeset} of {FORMULAS} formulas typeset: {text}"
    assert "\\(" not in text
    assert "\\[" not in text
    assert "Math Processing Error" not in text


def test_without_the_shipped_mathjax_the_formulas_stay_raw(site: Path, tmp_path: Path) -> None:
    """The negative control: the rendering above comes from the copy in the site."""
    bare = tmp_path / "bare"
    shutil.copytree(site, bare, ignore=shutil.ignore_patterns("mathjax"))
    seen = rendered(bare / "index.html", tmp_path)
    assert seen.typeset == 0
    assert "\\(\\kappa^*" in "".join(seen.text)
