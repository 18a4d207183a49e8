"""The output layer: a solved problem's profile, summary and roller table
(:mod:`.results`), the lay design columns and code checks of the summary
(:mod:`.design`), Parquet writing with units (:mod:`.io`) and the figure of
one case (:mod:`.plot`). It imports the input, kernels and engine layers."""
