"""Reusable widgets of the Kinema TUI."""
