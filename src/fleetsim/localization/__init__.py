"""Localization: amcl and fake_localization."""
