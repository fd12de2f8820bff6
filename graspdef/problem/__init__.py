"""Loads, supports and the Problem every solver receives."""
