"""otonav."""
