"""Transports that carry a context's topics beyond its process (Zenoh)."""
