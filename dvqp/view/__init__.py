"""The arm on the pipe in 3-D: its geometry (:mod:`dvqp.view.scene3d`), a still PNG
(:mod:`dvqp.view.still`, matplotlib) and an interactive view in the browser
(:mod:`dvqp.view.server`, the extra ``dvqp[view]``)."""
