"""Kirchhoff-Love thin shells on Loop-subdivision surfaces: kinematics, materials and energy."""
