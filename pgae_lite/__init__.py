"""pgae_lite."""
