"""Workflows built on training and evaluation: the thesis reproduction and comparison, Ray Tune
campaigns, run tables, the baseline tables."""
