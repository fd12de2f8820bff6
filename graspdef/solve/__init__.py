"""Solvers: sparse direct KKT solves and the linear problem (Hessian at rest)."""
