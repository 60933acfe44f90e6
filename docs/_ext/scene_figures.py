"""sphinx-gallery image scraper for the figures an example hands to its scene.

mbsuite's figures are pyplot-free :class:`matplotlib.figure.Figure` objects (``core.plot``), which
sphinx-gallery's matplotlib scraper, reading pyplot's figure manager, does not see.  An example run
by hand queues every figure it passes to ``scene.figure(...)`` (:func:`core.scenes.figures_to_show`);
this scraper saves the queued figures of a code block as the block's images.
"""

from __future__ import annotations


def scene_figure_scraper(block, block_vars, gallery_conf):
    """Save the figures queued since the last block; returns their reST (sphinx-gallery's scraper
    protocol: ``(block, block_vars, gallery_conf) -> str``)."""
    from sphinx_gallery.scrapers import figure_rst

    from core.scenes import figures_to_show

    paths = []
    for fig, path in zip(figures_to_show(), block_vars["image_path_iterator"]):
        fig.savefig(path, dpi=100)
        paths.append(path)
    return figure_rst(paths, gallery_conf["src_dir"])
