"""Crack policies: which patch edges share a curve, and the factor they agree on."""
