"""Modal dialogs of the Kinema TUI."""
