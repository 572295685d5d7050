"""The alternatives an error message offers for a name it does not know."""

from __future__ import annotations

from kinema.errors import did_you_mean


def test_a_cut_listing_still_shows_the_names_it_suggests() -> None:
    # An objective's parameters, the one meant sorting last: it was cut from "Valid:" while suggested.
    ports = [f"{prefix}_scale_factor" for prefix in "abcdefghi"] + ["waypoint_name"]
    text = did_you_mean("waypoint", ports)
    assert text.startswith("did you mean 'waypoint_name'? Valid: ")
    assert "waypoint_name, … (10 in all)" in text
    assert text.count(",") == 8  # eight names shown, then the count


def test_a_short_listing_is_whole_and_sorted() -> None:
    assert did_you_mean("elbo", ["wrist", "elbow"]) == "did you mean 'elbow'? Valid: elbow, wrist"
    assert did_you_mean("zzz", ["b", "a"]) == "valid: a, b"
    assert did_you_mean("x", []) == "there are none"
