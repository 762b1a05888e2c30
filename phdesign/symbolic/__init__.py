"""The symbolic layer: model, expressions, ports, observer and propositions (sympy only)."""
