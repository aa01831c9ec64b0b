"""Continuation recipes: which AUTO runs to make, in what order, with which constants."""
