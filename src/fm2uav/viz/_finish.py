"""The last step of a multi-panel figure: the title over a line of its numbers, tight layout."""

from __future__ import annotations

from matplotlib.figure import Figure

__all__ = ["finish"]


def finish(fig: Figure, title: str | None, sub: str, *, fontsize: int = 11) -> Figure:
    """``fig`` with the suptitle ``title`` over ``sub`` (``sub`` alone without a title),
    laid out tight.

    Examples
    --------
    >>> fig = finish(Figure(), "plan", "length 10 m")
    >>> fig.texts[0].get_text()
    'plan\\nlength 10 m'
    """
    fig.suptitle(f"{title}\n{sub}" if title else sub, fontsize=fontsize)
    fig.tight_layout()
    return fig
