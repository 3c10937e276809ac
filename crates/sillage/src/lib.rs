//! Facade of the sillage toolkit: re-exports and the pipeline built from one configuration.
