"""The garbage collector, held while the TUI draws its first frame, and kept off the objects made for it.

Importing Textual and composing the first screen make ~10^5 objects that live as long as the app. The
collector runs every 700 allocations and walks more of them each time, finding almost nothing to free.
:func:`hold` turns it off before the app's modules are imported; :func:`settle`, after the first frame,
freezes what lives then (``gc.freeze``), so that no later collection walks it again (a full one took
hundreds of ms while the blackboard streamed), and turns the collector back on. The start-up's few
thousand unreachable objects (under 1 MB) are frozen with the rest rather than collected: a collection
then would walk the whole heap on the UI thread, while the user starts typing.
"""

from __future__ import annotations

import gc

_held = False


def hold() -> None:
    """Turn the collector off until :func:`settle` (``kinema ui`` calls this before it imports the app)."""
    global _held
    if gc.isenabled():
        gc.disable()
        _held = True


def settle() -> None:
    """After the first frame: freeze what lives, and turn the collector back on if :func:`hold` held it."""
    gc.freeze()
    release()


def release() -> None:
    """Turn the collector back on if :func:`hold` turned it off; one that was off before stays off."""
    global _held
    if _held:
        _held = False
        gc.enable()
