"""The api layer: :func:`pipelay_fast.solve` (:mod:`.solve`) and the target
solve :func:`pipelay_fast.solve_for` (:mod:`.target`), the entry points that
turn a validated case into a :class:`~pipelay_fast.output.results.Result`."""
