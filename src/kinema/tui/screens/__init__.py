"""The screens of the Kinema TUI, one per area (the app's modes)."""
