"""Plugins: distributions of mu_s and temperature drivers, their registry and their contract."""
