"""core.scene.pipeline."""
