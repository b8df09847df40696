"""Min-warping's one-off work in a run's worker server (the method's ``preload_modules``): the
default parameters' admissible pairs (:func:`~homebench.methods.min_warping.search
.search_template`, kept per process) traced before the server forks, which every worker would
otherwise trace at its first pair (0.4 s of CPU). Not done where the kernels load: warping-2d's
scale-plane scheme loads them and never reads these pairs.
"""

from __future__ import annotations

from homebench.methods.min_warping.method import MinWarping
from homebench.methods.min_warping.search import search_template

_DEFAULT = MinWarping()
search_template(_DEFAULT.band_columns, _DEFAULT.n_scales, _DEFAULT.max_scale)
