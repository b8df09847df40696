"""Tables, figures and the PDF report."""

#: Goals per condition whose home-vector fields and AE maps a grid report draws (the
#: appendix of its documents), spread over the goal list, unless told otherwise.
DEFAULT_MAX_GOALS = 2
