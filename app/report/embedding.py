"""Bokeh figures embedded in a page that opens offline: their script, their divs, and BokehJS with
its styles inline (no external script or stylesheet).
"""

from __future__ import annotations

from dataclasses import dataclass

from bokeh.document import Document
from bokeh.embed import components
from bokeh.embed.bundle import bundle_for_objs_and_resources
from bokeh.io.doc import patch_curdoc
from bokeh.resources import INLINE


@dataclass(frozen=True)
class EmbeddedFigures:
    """What a page needs to show some Bokeh figures offline."""

    script: str  # the figures' data and the script that renders them into the divs
    divs: dict[str, str]  # name -> the div that shows the figure
    resources: str  # BokehJS and its styles as inline <script> and <style> elements


def embed_inline(figures: dict) -> EmbeddedFigures:
    """Embed ``figures`` (name -> Bokeh model) with everything they need inline."""
    # bokeh's embedding asks curdoc() for its settings; in a served callback that can be another
    # session's document (bokeh keeps one global stack of patched documents for all threads),
    # destroyed by the time it is read: give it a fresh one of its own
    fresh = Document()
    with patch_curdoc(fresh):
        script, divs = components(figures)
    # only what these figures need, inline: BokehJS and its styles as text.  Files to load
    # (``bundle.js_files``: Panel adds its module shim to every bundle once imported) are left
    # out: they would be fetched from a server, and plain Bokeh figures do not use them
    bundle = bundle_for_objs_and_resources(list(figures.values()), INLINE)
    resources = "\n".join([*(f"<style>{css}</style>" for css in bundle.css_raw),
                           *(f"<script>{js}</script>" for js in bundle.js_raw)])
    return EmbeddedFigures(script, divs, resources)
