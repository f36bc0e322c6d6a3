"""Measuring step 04 beside Embree: bench04.py (./workbook bench) and bvh_check.sh."""
