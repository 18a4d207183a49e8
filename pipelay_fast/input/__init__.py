"""The input layer: the case file's tables (pipe, environment, lay, solver,
checks), their validation, the steel grades, the model's limits and
:class:`SolveError`. It imports nothing else of the package."""
