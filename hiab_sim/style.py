"""One visual language: one colour and one marker per design, used by every figure, map and video.

Colours are from the Okabe-Ito palette (distinguishable with the common colour-vision
deficiencies and in greyscale by lightness): the initial design blue, the optimal design bluish
green, the rounded (buildable) design reddish purple, the hydraulic baseline vermillion (the
only warm colour, so the optimum never reads as the hydraulic crane), the reference black.
"""

from __future__ import annotations

#: Matplotlib colour (hex) of each design and of the other curves a figure shows.
COLOURS: dict[str, str] = {
    "initial": "#0072B2",  # blue
    "optimal": "#009E73",  # bluish green
    "rounded": "#CC79A7",  # reddish purple
    "hydraulic": "#D55E00",  # vermillion
    "reference": "#000000",  # black
}

#: Marker of each design in scatter plots (operating points on the maps).
MARKERS: dict[str, str] = {"initial": "o", "optimal": "s", "rounded": "D", "hydraulic": "^", "reference": "x"}


def colour(design: str) -> str:
    """The hex colour of a design (``initial``, ``optimal``, ``rounded``, ``hydraulic``, ``reference``)."""
    try:
        return COLOURS[design]
    except KeyError:
        raise KeyError(f"no colour for design {design!r}; known: {sorted(COLOURS)}") from None


def rgba(design: str, alpha: float = 1.0) -> tuple[float, float, float, float]:
    """The colour of a design as an RGBA tuple in [0, 1] (MuJoCo geoms, video captions)."""
    h = colour(design).lstrip("#")
    r, g, b = (int(h[i : i + 2], 16) / 255.0 for i in (0, 2, 4))
    return (r, g, b, float(alpha))
