"""Wheel-rail contact search: the four conditions of Pombo, Ambrosio & Silva (2007), all wheels at once.

:class:`ContactSearch` is a thin class composed of one part per concern, each in its module:

* :mod:`railway.contact.search.contact_search` -- :class:`ContactSearch`: its parameters, the
  public calls (``search``, ``scan_seeds``, ``solve``, ``solve_pairs``, ``reset``) and the pose
  checks; the whole method in its module docstring;
* :mod:`railway.contact.search.seeds` -- the seed scan: global re-seeding over the profile grid;
* :mod:`railway.contact.search.newton` -- the Newton solve of the four conditions;
* :mod:`railway.contact.search.robust` -- the robust refinement where Newton fails (minimum of
  the profile-line gap);
* :mod:`railway.contact.search.zones` -- zone bookkeeping: tread and flange candidates,
  duplicates, validity, warm starts, multistart;
* :mod:`railway.contact.search.result` -- :class:`ContactResult`, :data:`TREAD`, :data:`FLANGE`;
* :mod:`railway.contact.search.pose` -- :func:`wheelset_pose`;
* :mod:`railway.contact.search.kernels` -- the Newton iteration, seed scan and robust
  minimisation compiled with numba (the numpy code is the reference; tests compare both).
"""

from .contact_search import ContactSearch
from .pose import wheelset_pose
from .result import FLANGE, TREAD, ContactResult
from .seeds import scan_lead_angle

__all__ = ["FLANGE", "TREAD", "ContactResult", "ContactSearch", "scan_lead_angle", "wheelset_pose"]
