"""Running the engine over many inputs: batching rows and the worker pool."""
