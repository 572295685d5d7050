"""The 3D view: a meshcat scene in the browser that follows a running runtime (``kinema view``).

The runtime never imports this package; the view is a read-only subscriber (see :mod:`kinema.viz.view`
to start one, :mod:`kinema.viz.scene_viewer` for what it subscribes to).
"""
