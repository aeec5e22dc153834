"""Tests of auvplan.optimization."""
