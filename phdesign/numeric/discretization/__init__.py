"""Structure-preserving discretizations: the port-Hamiltonian result type and its methods."""
