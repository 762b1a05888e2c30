"""Regenerate the README gallery: three pictures of the paper's beam, in docs/gallery/.

Usage: ``python benchmarks/gallery.py [--out docs/gallery]`` (about 20 s).

1. ``beam_deflection.png``: deflection w(z, t), its estimate ŵ, the error w − ŵ and the
   end tip for design 2 of the paper, L = diag(0.1, 1) (its Figs. 2 to 4).
2. ``beam_designs.png``: end-tip error and H̃(t)/H̃(0) of the paper's three designs
   (its Figs. 5 and 6).
3. ``beam_gain_map.png``: spectral abscissa of the error system over (l1, l2), the three
   designs and the gain of ``phdesign tune``.

Each file must stay under 200 kB (the script fails otherwise).
"""

from __future__ import annotations

import argparse
import io
import sys
from pathlib import Path

import numpy as np

from phdesign import plots
from phdesign.models import load_builtin
from phdesign.numeric.bridge import to_numeric
from phdesign.numeric.inputs import initial_state_function
from phdesign.numeric.spectrum.evaluator import AbscissaEvaluator
from phdesign.numeric.time.options import SimulationOptions
from phdesign.numeric.time.simulation import simulate
from phdesign.numeric.tuning.search import tune

MAX_BYTES = 200_000
DESIGNS = {"design 1": (0.03, 0.3), "design 2": (0.1, 1.0), "design 3": (0.2, 2.0)}


def save(fig, path: Path) -> int:
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=90)
    data = buffer.getvalue()
    if len(data) > MAX_BYTES:
        raise SystemExit(f"{path.name}: {len(data)} bytes > {MAX_BYTES}; lower the dpi or size")
    path.write_bytes(data)
    return len(data)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default=str(Path(__file__).resolve().parents[1] / "docs/gallery"))
    args = parser.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)

    beam = load_builtin("euler-bernoulli")
    nm = to_numeric(beam)
    C = np.array([[0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]])  # sensors y3, y4
    x0 = initial_state_function("x1: 0, x2: z - 0.9", nm, model=beam)
    runs = {
        name: simulate(
            nm,
            C,
            np.diag(g),
            x0=x0,
            options=SimulationOptions(t_end=5.0, samples=401, z_w=np.linspace(0, 1, 41)),
        )
        for name, g in DESIGNS.items()
    }
    labels = {name: f"{name}, L = diag{g}" for name, g in DESIGNS.items()}

    fig = plots.plot_deflection_panels(runs["design 2"])
    fig.suptitle("Euler-Bernoulli beam, observer from zero, L = diag(0.1, 1) (paper, Figs. 2-4)")
    sizes = {"beam_deflection.png": save(fig, out / "beam_deflection.png")}

    fig, axes = plots.new_figure(1, 2, figsize=(11, 4))
    relabelled = {labels[k]: v for k, v in runs.items()}
    plots.plot_tip_error(relabelled, ax=axes[0])
    plots.plot_error_energy(relabelled, ax=axes[1])
    fig.suptitle("The paper's three designs: weakly, critically and over-damped (Figs. 5-6)")
    sizes["beam_designs.png"] = save(fig, out / "beam_designs.png")

    # the abscissa of spectrum() at the pair (20, 30), prepared once for the 36 x 36 gains
    evaluator = AbscissaEvaluator(nm, C, (20, 30))
    l1 = np.logspace(-2.5, 0.0, 36)
    l2 = np.logspace(-1.5, 1.3, 36)
    alpha = evaluator.abscissas([np.diag([a, b]) for b in l2 for a in l1]).reshape(36, 36)
    tuned = tune(nm, C)
    g = (float(tuned.gain[0, 0]), float(tuned.gain[1, 1]))
    fig = plots.plot_gain_map(
        l1,
        l2,
        alpha,
        optimum=g,
        optimum_abscissa=tuned.spectral_abscissa,
        designs={k.split()[-1]: v for k, v in DESIGNS.items()},
    )
    sizes["beam_gain_map.png"] = save(fig, out / "beam_gain_map.png")
    for name, size in sizes.items():
        print(f"{out / name}: {size / 1000:.0f} kB")
    return 0


if __name__ == "__main__":
    sys.exit(main())
