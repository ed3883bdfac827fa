"""The physical model: networks of sliders and springs, their builders, physical units."""
