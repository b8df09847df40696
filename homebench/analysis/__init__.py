"""The analysis: pure functions of a run's result tables, read by the engine, the report and
the API. Metrics (AE, AHC, RR, catchment: :mod:`.metrics`, :mod:`.return_ratio`), the run's
tables (:mod:`.tables`), statistics (goal-bootstrap intervals and tests: :mod:`.statistics`,
:mod:`.unpaired`), comparisons of methods and runs (:mod:`.comparisons`, :mod:`.worlds`) and
the papers' findings (:mod:`.findings`). Nothing here reads a file or starts a worker."""
