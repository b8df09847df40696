"""Grid databases: the model, manifests, loaders, checksums, generated worlds."""
