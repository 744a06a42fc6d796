# Reference values of the Shapiro-Wilk test from R's shapiro.test (Royston's AS R94), for
# modules/rawgment/test/test_normality.cpp. The tests read the committed output and need no R.
#
# Regenerate (Debian package r-base-core):
#   Rscript modules/rawgment/test/data/make_shapiro_reference.R > modules/rawgment/test/data/shapiro_reference.csv
#
# One line per case: distribution,n,W,p,x_1 x_2 ... x_n (unsorted, as drawn). Samples are rounded to
# 12 significant digits *before* the test so that the stored text is exactly the data R tested; every
# number is printed with 17 significant digits, which round-trips an IEEE double.
set.seed(20231120)
sizes <- c(3, 4, 5, 6, 7, 10, 11, 12, 19, 20, 21, 50, 100, 500, 1000, 2000, 5000)
draw <- list(
  normal = function(n) rnorm(n),
  normal_offset = function(n) rnorm(n, mean = 60000, sd = 3),
  uniform = function(n) runif(n),
  exponential = function(n) rexp(n),
  lognormal = function(n) rlnorm(n),
  student_t3 = function(n) rt(n, df = 3),
  integer_ties = function(n) rpois(n, lambda = 2)
)
fmt <- function(v) formatC(v, digits = 17, format = "g")
cat(R.version.string, file = stderr(), "\n")
for (name in names(draw)) {
  for (n in sizes) {
    repeat {
      x <- signif(draw[[name]](n), 12)
      if (max(x) > min(x)) break # shapiro.test rejects constant samples
    }
    r <- shapiro.test(x)
    cat(name, n, fmt(unname(r$statistic)), fmt(r$p.value), paste(fmt(x), collapse = " "), sep = ",")
    cat("\n")
  }
}
