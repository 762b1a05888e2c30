"""Commands ``certify`` and ``check``: a proved spectral abscissa, and its re-check.

``phdesign certify MODEL [--sensors 3,4 --gain 0.1,1] [--band W] [--rate] [-o proof.json]``
prints the certificate (``str()`` of :meth:`phdesign.Observer.certify` or
:meth:`phdesign.Plant.certify`) and writes the proof file; ``phdesign check proof.json``
re-verifies a proof file with the independent checker (:mod:`phdesign.proofcheck`,
which loads neither python-flint nor numpy): exit status 0 when every claim holds, 1
when the proof is rejected (each failure on a line of its own), 2 for a file that
cannot be read.
"""

from __future__ import annotations

import argparse

from phdesign.cli.common import (
    add_json_argument,
    add_model_argument,
    add_quiet_argument,
    emit,
    emit_json,
    load_model,
    run_outputs,
)
from phdesign.cli.design_arguments import add_observer_arguments, observer_from_args
from phdesign.core.errors import OutputFileError

__all__ = ["register"]


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the ``certify`` and ``check`` commands."""
    cert = subparsers.add_parser(
        "certify",
        help="prove the spectral abscissa of the plant or the error system (proof file)",
        description=(
            "Prove the spectral abscissa of the plant (u = 0) or, with --sensors/--cm and "
            "--gain, of the observer's error system, in ball arithmetic (python-flint, the "
            "extra 'certify'): over the whole plane for first-order systems with one travel "
            "time and P0 = 0, else over the band |Im λ| <= --band.  -o writes the proof "
            "file that 'phdesign check' re-verifies."
        ),
    )
    add_model_argument(cert)
    add_observer_arguments(cert, required=True)
    cert.add_argument(
        "--band",
        type=float,
        metavar="W",
        help="prove the band |Im λ| <= W (needed unless the whole plane can be proved)",
    )
    cert.add_argument(
        "--rate", action="store_true", help="also prove a decay rate sigma and constant M"
    )
    cert.add_argument("--output", "-o", metavar="FILE", help="write the proof file (JSON)")
    cert.add_argument("--force", action="store_true", help="overwrite an existing file")
    add_json_argument(cert)
    add_quiet_argument(cert)
    cert.set_defaults(handler=_certify, plot=None)
    check = subparsers.add_parser(
        "check",
        help="re-verify a proof file with the independent checker",
        description=(
            "Re-verify a proof file written by 'phdesign certify' with an independent "
            "implementation (mpmath's interval arithmetic and exact rationals; no flint, no "
            "numpy).  Exit status 0: verified; 1: rejected (the failures are listed)."
        ),
    )
    check.add_argument("proof", metavar="PROOF", help="the proof file (JSON)")
    add_json_argument(check)
    check.set_defaults(handler=_check)


def _certify(args: argparse.Namespace) -> int:
    from phdesign.design.plant import Plant
    from phdesign.io import dumps_json

    model = load_model(args)
    observer = observer_from_args(args, model, command="certify")
    with run_outputs(args) as commit:
        if observer is None:
            cert = Plant(model).certify(args.band, rate=args.rate)
        else:
            cert = observer.certify(args.band, rate=args.rate)
        if args.output:
            commit(dumps_json(cert.to_dict()), cert)
    if args.json:
        emit_json(cert.to_dict())
    else:
        emit(str(cert))
    return 0


def _check(args: argparse.Namespace) -> int:
    import json

    from phdesign.proofcheck import check_proof

    try:
        with open(args.proof, encoding="utf-8") as handle:
            proof = json.load(handle)
    except OSError as error:
        raise OutputFileError(
            f"cannot read the proof file {args.proof!r}: {error.strerror}"
        ) from None
    except (json.JSONDecodeError, UnicodeDecodeError) as error:
        raise OutputFileError(f"the proof file {args.proof!r} is not JSON: {error}") from None
    failures = check_proof(proof)
    claim = proof.get("claim", {}) if isinstance(proof, dict) else {}
    if args.json:
        emit_json({"verified": not failures, "failures": failures, "claim": claim})
    elif failures:
        emit("\n".join(["rejected:", *(f"  - {f}" for f in failures)]))
    else:
        emit(_verified_text(proof))
    return 1 if failures else 0


def _verified_text(proof: dict) -> str:
    from fractions import Fraction

    claim = proof["claim"]
    interval = claim.get("abscissa_interval")
    where = "the whole plane" if claim.get("whole_plane") else f"|Im λ| <= {claim.get('band')}"
    lines = ["verified: every claim of the proof file holds"]
    if "band" not in proof and "whole_plane" not in proof:
        lines.append("  no spectrum section: the spectral abscissa is not claimed")
    elif interval is None:
        lines.append(f"  no eigenvalue in {where} (right of the proof's left edge)")
    else:
        lo, hi = (float(Fraction(x)) for x in interval)
        lines.append(f"  spectral abscissa in [{lo:.12g}, {hi:.12g}] over {where}")
    if "rate" in proof:
        lines.append("  the decay-rate section verified")
    return "\n".join(lines)
