"""Frames of a world as arrays (RGB, ANSI), the matplotlib viewer and GIF output, the envs'
renderer."""
