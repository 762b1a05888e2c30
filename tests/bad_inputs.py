"""Bad model files shared by the library tests and the command-line table.

Each row: (changes to the beam's model file, the exception the library raises, a regex
that the message must match: it names the culprit and gives expected against found).
"""

from __future__ import annotations

import copy
import tomllib

from phdesign.core.errors import (
    ExpressionError,
    ModelError,
    ModelFileError,
    PortError,
    ShapeError,
)
from phdesign.models import builtin_toml

BEAM = tomllib.loads(builtin_toml("euler-bernoulli"))


def beam_with(**changes):
    """The beam's model-file content with keys replaced; a value None deletes the key."""
    data = copy.deepcopy(BEAM)
    for path, value in changes.items():
        keys = path.split("__")
        table = data
        for key in keys[:-1]:
            table = table[key]
        if value is None:
            del table[keys[-1]]
        else:
            table[keys[-1]] = value
    return data


def tip_mass(**changes):
    """A tip mass's [[boundary_systems]] table for the beam's input 4, with keys replaced."""
    table = {"name": "mass", "ports": [4], "J": [[0]], "R": [[0]], "Q": [[1]], "G": [[1]]}
    return {**table, **changes}


# (changes to the beam file, exception, regex naming the culprit)
BAD_MODELS = [
    ({"order": 0}, ModelError, "order must be an integer N >= 1; found 0"),
    ({"order": "2"}, ModelError, "order must be an integer"),
    ({"interval": [1, 0]}, ModelError, r"a < b; found \[1, 0\]"),
    ({"interval": [0]}, ModelError, r"interval must be a pair"),
    ({"interval": [0, "nan"]}, ExpressionError, "unknown symbol 'nan'"),
    ({"interval": [0, float("inf")]}, ExpressionError, "finite number"),
    ({"matrices__P2": [[0, 1], [1, 0]]}, ModelError, r"P2 must satisfy P2\^T = -P2"),
    ({"matrices__P1": [[0, 1], [0, 0]]}, ModelError, r"P1 must satisfy P1\^T = P1"),
    (
        {"matrices__P0": [[1, 0], [0, 0]]},
        ModelError,
        "P0 \\+ P0\\^T must be negative semidefinite",
    ),
    (
        {"matrices__P0": [["d", 0], [0, 0]]},
        ModelError,
        "negative semidefinite \\(exact at the parameter defaults\\)",
    ),
    (
        {"matrices__P2": [[0, 0], [0, 0]]},
        ModelError,
        r"P2 must be invertible; found det\(P2\) = 0",
    ),
    ({"matrices__P3": [[0, 0], [0, 0]]}, ModelError, "P3 is not a matrix of an order-2 model"),
    ({"matrices__Q": [[1]]}, ModelFileError, "unknown matrix 'Q'"),
    ({"matrices__H": None}, ModelFileError, "lacks H"),
    ({"matrices__H": [[1, 1], [0, 1]]}, ModelError, "H must be symmetric"),
    ({"matrices__H": [[1, 0], [0, -1]]}, ModelError, "H must be positive definite"),
    (
        {"matrices__H": [["z - 0.5", 0], [0, 1]]},
        ModelError,
        # exact: the minor z - 1/2 has minimum -1/2 on [0, 1] (at z = 0)
        r"found leading principal minor 1 = z - 1/2 with minimum -1/2",
    ),
    (
        {"matrices__H": [["cos(3*z)", 0], [0, 1]]},
        ModelError,
        # grid: cos(3 z) decreases on [0, 1] (its first zero is pi/6), cos(3) = -0.989992
        r"smallest eigenvalue -0.989992 at z = 1 \(parameter defaults\)",
    ),
    ({"matrices__H": [["1/z", 0], [0, 1]]}, ModelError, "bounded on"),
    (
        {"matrices__H": [[1, 0, 0], [0, 1, 0], [0, 0, 1]]},
        ShapeError,
        r"P0 matrix; expected \(3, 3\) but found \(2, 2\)",
    ),
    ({"matrices__H": [[1, 0], [0]]}, ModelError, "H row 2 has 1 entries; expected 2"),
    ({"matrices__H": [["1/rho", 0], [0, "EJ"]]}, ExpressionError, "unknown symbol 'EJ'"),
    (
        {"matrices__P2": [[0, "-z"], ["z", 0]]},
        ExpressionError,
        "spatial variable z is not allowed",
    ),
    (
        {"matrices__P0": [["-d", 0], [0, True]]},
        ExpressionError,
        r"P0\[2,2\] must be a number; found the boolean",
    ),
    ({"parameters__d": "abc"}, ExpressionError, "unknown symbol 'abc'"),
    ({"parameters__z": 1.0}, ExpressionError, "parameter name 'z' is reserved"),
    ({"parameters__e1": 1.0}, ExpressionError, "parameter name 'e1' is reserved"),
    ({"parameters__rho": -1}, ModelError, "H must be positive definite"),
    (
        {"ports__inputs": ["e1(0)", "e1'(0)", "e2(1)"]},
        ModelError,
        "needs N\\*n = 4 inputs; found 3",
    ),
    (
        {"ports__outputs": ["e2'(0)", "-e2(0)", "e1'(1)", "-e1(1)", "e1(0)"]},
        ModelError,
        "4 outputs; found 5",
    ),
    (
        {"ports__inputs": ["e1(0)", "e1''(0)", "e2(1)", "e2'(1)"]},
        ExpressionError,
        r"inputs\[2\].*derivative order 2",
    ),
    ({"ports__inputs": ["e1(0)", "e1'(0.5)", "e2(1)", "e2'(1)"]}, ExpressionError, "interior"),
    (
        {"ports__inputs": ["e1(0)", "e3'(0)", "e2(1)", "e2'(1)"]},
        ExpressionError,
        r"expected 1..2, found 3",
    ),
    (
        {"ports__inputs": ["e1(0)*e1(1)", "e1'(0)", "e2(1)", "e2'(1)"]},
        ExpressionError,
        "not linear",
    ),
    (
        {"ports__inputs": ["e1(0)", "e1'(0)", "e2(1)", "os.system('x')"]},
        ExpressionError,
        "unexpected character",
    ),
    (
        {"ports__outputs": ["e2'(0)", "e2(0)", "e1'(1)", "-e1(1)"]},
        PortError,
        r"W_C Σ W_Bᵀ = I fails",
    ),
    (
        {"ports__outputs": ["e2'(0)", "e2'(0)", "e1'(1)", "-e1(1)"]},
        PortError,
        "outputs are linearly dependent",
    ),
    ({"ports__inputs": "e1(0)"}, ModelError, "inputs must be a list"),
    (
        {"ports__inputs": [["e1(0)"], "e1'(0)", "e2(1)", "e2'(1)"]},
        ExpressionError,
        r"inputs\[1\] must be a trace expression such as \"e1\(0\)\"; found list",
    ),
    (
        {"ports__extra": ["e1(0)"]},
        ModelFileError,
        r"\[ports\] must hold exactly inputs and outputs",
    ),
    ({"name": None}, ModelFileError, "lacks the key\\(s\\) name"),
    ({"colour": "blue"}, ModelFileError, "unknown key\\(s\\) colour"),
    ({"matrices": [1, 2]}, ModelFileError, "matrices must be a table"),
    (
        {"displacement": {"component": 3, "integrations": 2}},
        ModelError,
        "displacement must name a component in 1..2",
    ),
    (
        {"displacement": {"component": "x2"}},
        ModelFileError,
        r"\[displacement\] must hold integers",
    ),
    ({"states": ["a"]}, ModelError, "state_names must hold 2 labels; found 1"),
    # --- issue 13 (model): [feedback], P0(z), outputs = "conjugate", [units]
    (
        {"feedback": {"inputs": [5], "gain": [[1]]}},
        ModelError,
        r"feedback.inputs\[1\] = 5 is not an input of the model; expected an index in 1..4",
    ),
    (
        {"feedback": {"inputs": [4, 4], "gain": [[1, 0], [0, 1]]}},
        ModelError,
        r"feedback.inputs\[2\] = 4 is repeated",
    ),
    (
        {"feedback": {"inputs": [4], "gain": [[-1]]}},
        ModelError,
        r"K \+ K\^T must be positive semidefinite \(exact\); found eigenvalues \[-2\]",
    ),
    (
        # K + Kᵀ = [[2, 3], [3, 2]] has eigenvalues -1 and 5: the skew part cannot hide it
        {"feedback": {"inputs": [3, 4], "gain": [[1, 3], [0, 1]]}},
        ModelError,
        r"K \+ K\^T must be positive semidefinite \(exact\); found eigenvalues \[-1, 5\]",
    ),
    (
        {"feedback": {"inputs": [4], "gain": [["-d"]]}},
        ModelError,
        r"K \+ K\^T must be positive semidefinite \(exact at the parameter defaults\)",
    ),
    ({"feedback": {"inputs": [4], "gain": [[1, 0]]}}, ModelError, "gain K must be square"),
    ({"feedback": {"inputs": [4]}}, ModelFileError, r"\[feedback\] must hold exactly inputs"),
    ({"feedback": {"inputs": 4, "gain": [[1]]}}, ModelError, "feedback.inputs must be a list"),
    ({"feedback": {"inputs": [4], "gain": [["z"]]}}, ExpressionError, "z is not allowed"),
    ({"feedback": {"inputs": [4], "gain": [["kk"]]}}, ExpressionError, "unknown symbol 'kk'"),
    (
        # 1/100 - (z - 1/2)² > 0 inside (0, 1): refused at the minimum of -(P0 + P0ᵀ)
        {"matrices__P0": [["0.01 - (z - 0.5)**2", 0], [0, 0]]},
        ModelError,
        r"negative semidefinite on \[0, 1\]; found principal minor \{1\} of -\(P0 \+ "
        r"P0\^T\) = 2\*z\*\*2 - 2\*z \+ 12/25 with minimum -1/50 at z = 1/2",
    ),
    (
        # grid: P0 + P0ᵀ = 2 cos(3z) is largest at z = 0
        {"matrices__P0": [["cos(3*z)", 0], [0, 0]]},
        ModelError,
        r"negative semidefinite on \[0, 1\]; found largest eigenvalue 2 at z = 0",
    ),
    ({"matrices__P0": [["-1/(z - 0.5)", 0], [0, 0]]}, ModelError, "has a pole there"),
    (
        {"matrices__P2": [[0, "-1 - z"], ["1 + z", 0]]},
        ExpressionError,
        "derived for constant P_1..P_N; only P0 and H may depend on z",
    ),
    (
        # velocity and shear force at z = 0 are conjugate: both cannot be imposed
        {"ports__inputs": ["e1(0)", "e2'(0)", "e2(1)", "e2'(1)"], "ports__outputs": "conjugate"},
        PortError,
        r"inputs are not admissible: .*inputs\[1\] = e1\(0\) and inputs\[2\] = e2'\(0\) "
        "exchange power",
    ),
    (
        {"ports__inputs": ["e1(0)", "e1'(0)", "e2(1)", "e2'(1) + e1(1)"], "ports__outputs": None},
        PortError,
        r"inputs\[4\] = e1\(1\) \+ e2'\(1\) carries power by itself.*close it with \[feedback\]",
    ),
    ({"ports__outputs": "conjugated"}, ModelFileError, "a list of trace expressions or"),
    ({"units": "SI"}, ModelFileError, "units must be a table"),
    ({"units": {"t": "$s$"}}, ModelError, r"units.t = '\$s\$' is malformed"),
    ({"units": {"t": 1}}, ModelError, "units.t must be text"),
    ({"units": {"z": "m" * 40}}, ModelError, "at most 32 characters"),
    ({"units": {"speed": "m/s"}}, ModelError, "units: unknown quantity 'speed'"),
    (
        {"units": {"x1": "kg/s", "momentum": "kg/s"}},
        ModelError,
        "'momentum' and 'x1' name the same state",
    ),
    # ---- issue 12: budgets before the work (each of these ran for minutes or GBs)
    (
        {"matrices__H": [["((z+1)**64)**64", 0], [0, 1]]},
        ExpressionError,
        r"has degree 4096 once built; expected at most 64",
    ),
    (
        # z*z*...*z is z**101: the exponent limit may not be bypassed by products
        {"matrices__H": [["1 + " + "*".join(["z"] * 101), 0], [0, 1]]},
        ExpressionError,
        r"has degree 101 once built; expected at most 64",
    ),
    (
        {"matrices__H": [["(1+z+z**2+z**3+z**4+z**5+z**6+z**7)**64", 0], [0, 1]]},
        ExpressionError,
        r"has degree 448 once built",
    ),
    (
        {"matrices__H": [["exp(1e300)", 0], [0, 1]]},
        ExpressionError,
        r"exp\(1000.*\) in 'exp\(1e300\)' is out of range",
    ),
    (
        {"matrices__H": [["exp(exp(exp(5)))", 0], [0, 1]]},
        ExpressionError,
        r"out of range; expected an argument of magnitude at most 691.5",
    ),
    (
        {"parameters": {f"p{i}": 1 for i in range(5000)}},
        ModelError,
        r"the model has 5000 parameters; expected at most 200",
    ),
    ({"interval": [0, "exp(800)"]}, ExpressionError, r"exp\(800\).*out of range"),
    ({"order": 9}, ModelError, r"order N is 9; expected at most 8"),
    # ---- issue 12 item 7: a sharp negative dip between grid points (width 1e-4, grid 5e-4)
    (
        {"matrices__H": [["1 - 1.5*exp(-100000000*(z - 0.50025)**2)", 0], [0, 1]]},
        ModelError,
        # at z = 0.50025 the entry is 1 - 1.5 = -0.5 exactly (the Gaussian's peak)
        r"found smallest eigenvalue -0.5 at z = 0.50025 \(parameter defaults\)",
    ),
    # ---- issue 12 item 9: state labels that --x0 would read as another component
    ({"states": ["x2", "x1"]}, ModelError, r"state label 'x2' of component 1 is ambiguous"),
    ({"states": ["e1", "curvature"]}, ModelError, r"'e1' of component 1 is ambiguous"),
    ({"states": ["w: 1", "curvature"]}, ModelError, r"holds a separator"),
    ({"states": ["momentum", "momentum"]}, ModelError, r"state labels must be distinct"),
    # ---- issue 26: boundary systems (a tip mass joined to the beam's shear-force input 4)
    (
        {"boundary_systems": [tip_mass(R=[[-1]])]},
        ModelError,
        r"boundary system 'mass' R_c must be positive semidefinite \(exact\); found "
        r"eigenvalues \[-1\]; its principal minor on rows and columns \{1\} is -1",
    ),
    (
        {"boundary_systems": [tip_mass(J=[[1]])]},
        ModelError,
        r"boundary system 'mass' J must be skew \(J_c = -J_c\^T.*found J_c \+ J_c\^T = \[\[2\]\]",
    ),
    (
        {"boundary_systems": [tip_mass(interconnection=[[0, 1], [1, 0]])]},
        ModelError,
        r"boundary system 'mass' interconnection must be skew \(S = -S\^T: power-preserving\); "
        r"found S \+ S\^T = \[\[0, 2\], \[2, 0\]\]",
    ),
    (
        {
            "boundary_systems": [
                tip_mass(Q=[[1, 2], [2, 1]], J=[[0, 0], [0, 0]], R=[[0, 0], [0, 0]], G=[[1], [0]])
            ]
        },
        ModelError,
        r"Q_c must be positive definite \(exact\); found eigenvalues \[-1, 3\]; its leading "
        r"principal minor on rows and columns \{1, 2\} is -3",
    ),
    (
        {"boundary_systems": [tip_mass(D=[[-1]])]},
        ModelError,
        r"'mass' D_c \+ D_c\^T must be positive semidefinite",
    ),
    (
        {"boundary_systems": [tip_mass(ports=[5])]},
        ModelError,
        r"'mass' ports\[1\] = 5 is not an input of the model; expected an index in 1..4",
    ),
    (
        {"boundary_systems": [tip_mass(states=["x1"])]},
        ModelError,
        r"the label 'x1' is a name phdesign reads already \(x<i> and e<i> are the field's",
    ),
    (
        {"boundary_systems": [tip_mass(states=["t"])]},
        ModelError,
        r"the label 't' is a name phdesign reads already",
    ),
    (
        {"boundary_systems": [tip_mass(), tip_mass(name="other")]},
        ModelError,
        r"'other' ports\[1\] = 4 is already closed by boundary system 'mass'",
    ),
    (
        {"boundary_systems": [tip_mass(G=[[1, 0]])]},
        ModelError,
        r"Incompatible dimensions of boundary system 'mass' G matrix; expected \(1, 1\) but "
        r"found \(1, 2\)",
    ),
    (
        {"boundary_systems": [tip_mass(mass=1)]},
        ModelError,
        r"boundary_systems\[1\]: expected the keys ports, J, R, Q, G .*unknown \['mass'\]",
    ),
    (
        {"boundary_systems": [tip_mass(R=[["q"]])]},
        ExpressionError,
        r"unknown symbol 'q'",
    ),
    (
        {"boundary_systems": {"name": "mass"}},
        ModelError,
        r"boundary_systems must be a list of boundary systems",
    ),
    # ---- issue 27: [disturbances], [ports] unknown, [performance]
    (
        {"disturbances": {"B": [[1], [0], [0]]}},
        ModelError,
        r"disturbances B matrix; expected \(2, q\) .* but found \(3, 1\)",
    ),
    ({"disturbances": {"B": [[1, 0], [0]]}}, ModelError, r"disturbances B row 2 has 1 entries"),
    ({"disturbances": {"B": [["kk"], [0]]}}, ExpressionError, r"unknown symbol 'kk'"),
    ({"disturbances": {"G": [[1], [0]]}}, ModelFileError, r"\[disturbances\] must hold exactly B"),
    ({"ports__unknown": [5]}, ModelError, r"ports.unknown\[1\] = 5 is not an input"),
    ({"ports__unknown": [2, 2]}, ModelError, r"ports.unknown\[2\] = 2 is repeated"),
    (
        {"performance": {"outputs": ["integral(e1*e2)"]}},
        ExpressionError,
        r"performance.outputs\[1\] 'integral\(e1\*e2\)'.*not linear in the efforts",
    ),
    (
        {"performance": {"outputs": ["w(1)", "e1(1)*e2(0)"]}},
        ExpressionError,
        r"performance.outputs\[2\] 'e1\(1\)\*e2\(0\)'.*not linear in the efforts",
    ),
    (
        {"performance": {"outputs": ["integral(e1(1))"]}},
        ExpressionError,
        r"performance.outputs\[1\].*integral\(\) of a trace: e1\(1\) is a boundary value",
    ),
    (
        {"performance": {"outputs": ["integral(e1) + 1"]}},
        ExpressionError,
        r"performance.outputs\[1\].*not linear in the efforts: it has the term 1",
    ),
    (
        {"performance": {"outputs": ["z*e1(1)"]}},
        ExpressionError,
        r"performance.outputs\[1\].*z is not allowed",
    ),
    (
        {"performance": {"outputs": ["w(2)"]}},
        ExpressionError,
        r"performance.outputs\[1\]: w\(2\) is outside the interval \[0, 1\]",
    ),
    (
        {"performance": {"outputs": ["integral(e3)"]}},
        ExpressionError,
        r"e3 in integral\(e3\) is out of range; expected components 1..2",
    ),
    (
        {"performance": {"outputs": ["w(1)", "w(1)"]}},
        ModelError,
        r"performance outputs: w\(1\) given twice",
    ),
]
