"""Flow: decorators that repeat their child and a condition that branches at random."""

from __future__ import annotations

from .biased_coin_flip import BiasedCoinFlip
from .repeat_unless_failure import RepeatUnlessFailureEachTick, RepeatUnlessFailureWithinTick

BEHAVIORS = (BiasedCoinFlip, RepeatUnlessFailureEachTick, RepeatUnlessFailureWithinTick)
