//! Classic motion laws (spec Appendix A) and the Table-3 catalogue of 7-segment vectors.
