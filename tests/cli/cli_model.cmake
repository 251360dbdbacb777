# `weft model`: table, JSON and sample output contents; invalid parameters fail with one line.

# Runs `weft model ARGS`, expects a non-zero exit and exactly one line on stderr matching PATTERN
# (a grep pattern without single quotes).
function(weft_model_error_test name pattern)
  add_test(NAME cli.model.error.${name}
           COMMAND sh -c "out=$(\"$0\" model \"$@\" 2>&1 >/dev/null); rc=$?; echo \"$out\"; \
[ $rc -ne 0 ] && [ $(printf '%s\\n' \"$out\" | wc -l) -eq 1 ] && printf '%s' \"$out\" | grep -q -- '${pattern}'"
                   $<TARGET_FILE:weft> ${ARGN})
  set_tests_properties(cli.model.error.${name} PROPERTIES LABELS cli)
endfunction()

# Runs `weft model ARGS` and pipes stdout into the shell CHECK (reads stdin).
function(weft_model_output_test name check)
  add_test(NAME cli.model.${name}
           COMMAND sh -c "set -e; \"$0\" model \"$@\" > model_${name}.out; { ${check}; } < model_${name}.out"
                   $<TARGET_FILE:weft> ${ARGN})
  set_tests_properties(cli.model.${name} PROPERTIES LABELS cli WORKING_DIRECTORY ${CMAKE_CURRENT_BINARY_DIR})
endfunction()

add_test(NAME cli.model.help COMMAND weft model --help)
set_tests_properties(cli.model.help PROPERTIES LABELS cli
                     PASS_REGULAR_EXPRESSION "--mean-extinction[^\n]*1/length.*--theta[^\n]*\\[length\\]")

# Default law, said so.
weft_model_output_test(default "grep -q 'default gamma law'")

# Eq. 20 with alpha = 0.5, mean 1 at t = 1 (x = 2): T_Q = 3^-0.5, p_Q = 3^-1.5, Sigma_Q = 1/3;
# reciprocal T_S = 3^-1.5 (shape 1.5, mean extinction 3), p_S = 3*3^-2.5, Sigma_S = 3/3 = 1.
weft_model_output_test(table
  "grep -E '^ +1 +0.5773502692 +0.1924500897 +0.3333333333 +0.1924500897 +0.1924500897 +1$' && \
grep -q 'l_Q = inf' model_table.out && grep -q 'l_S = 1$' model_table.out && \
test $(grep -c -v '^#' model_table.out) -eq 5"
  --law gamma --alpha 0.5 --mean-extinction 1 --t 0,1,10,100)

weft_model_output_test(json
  "grep -q '\"source\": \"infinite\"' && grep -q '\"scatterer\": 1.0' model_json.out && \
grep -q '\"T_Q\": 0.57735026918962' model_json.out && grep -q '\"alpha\": 1.5' model_json.out && \
test $(grep -c '\"Sigma_S\"' model_json.out) -eq 2"
  --law gamma --alpha 0.5 --mean-extinction 1 --t 0,1 --json)

# Paper parametrisation (sigma, alpha, beta) and concentration statistics give the same law.
weft_model_output_test(paper_parameters "grep -q '^ *1 *0.4444444444'"
  --law gamma --sigma 2 --alpha 2 --beta 4 --t 1)
weft_model_output_test(zero_variance_is_exponential "grep -q '^ *1 *0.3678794412 *0.3678794412 *1 '"
  --law gamma --sigma 2 --mean-concentration 0.5 --var-concentration 0 --t 1)

# 1000 exponential samples (mu = 2): count, non-negative, mean within 5 standard errors of 1/2.
weft_model_output_test(sample
  "awk '{ if ($1 < 0) bad = 1; s += $1 } END { m = s / NR; exit !(NR == 1000 && !bad && m > 0.42 && m < 0.58) }'"
  --law exponential --mu 2 --sample 1000 --seed 3)
add_test(NAME cli.model.sample_reproducible
         COMMAND sh -c "a=$(\"$0\" model --law gamma-path --k 0.5 --theta 1 --pair same --sample 50 --seed 9); \
b=$(\"$0\" model --law gamma-path --k 0.5 --theta 1 --pair same --sample 50 --seed 9); \
c=$(\"$0\" model --law gamma-path --k 0.5 --theta 1 --pair same --sample 50 --seed 10); \
[ \"$a\" = \"$b\" ] && [ \"$a\" != \"$c\" ]" $<TARGET_FILE:weft>)
set_tests_properties(cli.model.sample_reproducible PROPERTIES LABELS cli)
# Draws from the given law need only that law (as Python's Law.sample): gamma-path with k = 3 has
# no reciprocal partner (p_Q(0) = 0), yet its source draws are there; the JSON still names the
# pair asked for. Its scatterer draws stay refused (model_* rows of the bad-input catalogue).
weft_model_output_test(sample_given_law_only
  "test $(wc -l < model_sample_given_law_only.out) -eq 5 && awk '{ if (!($1 > 0)) exit 1 }'"
  --law gamma-path --k 3 --theta 0.5 --sample 5 --from source)
weft_model_output_test(sample_given_law_only_json "grep -q '\"pair\": \"reciprocal\"'"
  --law gamma-path --k 3 --theta 0.5 --sample 5 --from source --json)
# Integers are decimal whatever their spelling: a leading zero is not octal (010 draws ten, with
# the draws of seed 10), blanks around the digits are dropped; 0x10 is refused with its digits.
add_test(NAME cli.model.integers_are_decimal
         COMMAND sh -c "a=$(\"$0\" model --law exponential --mu 1 --sample 010 --seed 010); \
b=$(\"$0\" model --law exponential --mu 1 --sample ' 10 ' --seed 10); \
[ $(printf '%s\\n' \"$a\" | wc -l) -eq 10 ] && [ \"$a\" = \"$b\" ] && \
\"$0\" model --law exponential --mu 1 --sample 0x10 2>&1 >/dev/null | grep -q 'decimal digits (16), got 0x10'"
                 $<TARGET_FILE:weft>)
set_tests_properties(cli.model.integers_are_decimal PROPERTIES LABELS cli)
# Scatterer segments of the gamma pair: mean of T_S (alpha 3, mean 4/3 ... ) = l_S = 1/mean_extinction = 1.
weft_model_output_test(sample_scatterer
  "awk '{ s += $1 } END { m = s / NR; exit !(NR == 4000 && m > 0.85 && m < 1.15) }'"
  --law gamma --alpha 3 --mean-extinction 1 --sample 4000 --from scatterer --seed 5)

# gap-gamma (gap 0.3, mean 2, alpha 1.5) at t = 1: T_Q = 0.3 + 0.7*(7/3)^-1.5; T(inf) = gap, l_Q = inf;
# the scatterer partner is the gamma law with shape 2.5 (no gap).
weft_model_output_test(gap_gamma
  "grep -E '^ +1 +0.4963961012 ' && grep -E '^ +inf +0.3 +0 ' model_gap_gamma.out && \
grep -q 'l_Q = inf' model_gap_gamma.out && grep -q 'T_S: gamma (mean_extinction = 3.333333333, alpha = 2.5)' model_gap_gamma.out"
  --law gap-gamma --gap 0.3 --mean-extinction 2 --alpha 1.5 --t 0,1,inf)
# gamma-mixture from lists: parameters as numbered keys; 4000 draws escape (+inf) with
# probability weight_1 = 0.2: the count within 5 standard errors (sqrt(4000*0.16) = 25.3) of 800.
weft_model_output_test(gamma_mixture_json
  "grep -q '\"weight_2\": 0.8' && grep -q '\"mean_extinction_1\": 0.0' model_gamma_mixture_json.out && \
grep -q '\"source\": \"infinite\"' model_gamma_mixture_json.out"
  --law gamma-mixture --weights 0.2,0.8 --alpha 1,3 --mean-extinction 0,5 --t 0,1 --json)
# --sample with --json: one object whose "samples" are the numbers --sample prints (+inf as
# "infinite"), in order. The check drops --json (the first argument) and compares.
weft_model_output_test(sample_json
  "grep -q '\"count\": 300' model_sample_json.out && grep -q '\"from\": \"source\"' model_sample_json.out && \
grep -q '\"infinite\"' model_sample_json.out && test \"$(tail -n 1 model_sample_json.out)\" = '}' && \
s=$(sed -n '/\"samples\": \\[/,/^  \\]/p' model_sample_json.out | sed '1d' | sed '$d' | tr -d ' ,' | \
sed 's/\"infinite\"/inf/') && shift && t=$(\"$0\" model \"$@\") && test -n \"$t\" && test \"$s\" = \"$t\""
  --json --law gamma-mixture --weights 0.2,0.8 --alpha 1,3 --mean-extinction 0,5 --sample 300 --seed 4)
# --sample 0 draws nothing, as Python's Law.sample(0): no table, an empty "samples" with --json.
weft_model_output_test(sample_zero "test -z \"$(cat)\"" --law exponential --mu 1 --sample 0)
weft_model_output_test(sample_zero_json
  "grep -q '\"count\": 0' && grep -qF '\"samples\": []' model_sample_zero_json.out"
  --law exponential --mu 1 --sample 0 --json)
# The sampler chosen is recorded with the draws (the law's parameters and the sampled law's).
weft_model_output_test(sampler_json
  "test $(grep -c '\"sampler\": \"inversion\"') -eq 2 && grep -q '\"sampling\": \"inversion' model_sampler_json.out"
  --law gamma-path --k 2 --theta 1 --pair same --sampler inversion --sample 2 --json)
# Subnormal numbers are numbers (Python reads them too): mu = 1e-320 leaves T(1) = 1.
weft_model_output_test(subnormal_mu "grep -E '^ +1 +1 +9.99988867[0-9]*e-321 '" --law exponential --mu 1e-320 --t 1)
file(WRITE ${CMAKE_CURRENT_BINARY_DIR}/model_subnormal.csv "t,T\n0,1\n1,1e-320\n")
weft_model_output_test(subnormal_table "grep -E '^ +1 +9.99988867[0-9]*e-321 '"
  --law tabulated --table ${CMAKE_CURRENT_BINARY_DIR}/model_subnormal.csv --t 1)

weft_model_output_test(gamma_mixture_sample
  "awk '$1 == \"inf\" { n++ } END { exit !(NR == 4000 && n > 673 && n < 927) }'"
  --law gamma-mixture --weights 0.2,0.8 --alpha 1,3 --mean-extinction 0,5 --sample 4000 --seed 4)

weft_model_error_test(negative_alpha "alpha" --law gamma --alpha -1 --mean-extinction 1)
weft_model_error_test(nan_alpha "alpha" --law gamma --alpha nan --mean-extinction 1)
weft_model_error_test(zero_alpha "alpha must be > 0" --law gamma --alpha 0 --mean-extinction 1)
weft_model_error_test(negative_mu "mu" --law exponential --mu -2)
weft_model_error_test(not_a_number "--theta: .abc. is not a number" --law gamma-path --k 2 --theta abc)
# One spelling of numbers for every option (check_number_options, weft::parse_option_number):
# decimal with blanks around it dropped; hexadecimal and past double's range said as such.
weft_model_error_test(hexadecimal "--t: .0x1p3. is a hexadecimal number (write it in decimal)" --law exponential --mu 1
                      --t 0x1p3)
weft_model_error_test(past_range "--mu: .1e309. is past double.s range" --law exponential --mu 1e309 --t 1)
weft_model_output_test(blanks_around_numbers "grep -E '^ +5 +0.0067379'" --law exponential --mu " 1" --t " 5 ")
weft_model_error_test(misspelt_law "did you mean .gamma." --law gamme --alpha 1 --mean-extinction 1)
weft_model_error_test(incomplete_set "accepted set" --law gamma --alpha 1)
weft_model_error_test(no_reciprocal "infinite mean free path" --law gamma --alpha 0.5 --mean-extinction 1 --given S)
weft_model_error_test(no_reciprocal_k "p_Q(0) = +inf" --law gamma-path --k 0.5 --theta 1)
# p proportional to T (S.55-S.57) is the source law of the pair given as T_S; for alpha <= 1, l_S = inf.
weft_model_error_test(proportional_alpha "infinite mean free path"
  --law gamma --alpha 0.8 --mean-extinction 1 --given S --from source --sample 3)
weft_model_error_test(missing_table "cannot open" --law tabulated --table /nonexistent/weft-table.csv)
weft_model_error_test(negative_t "distances must be >= 0" --t 1,-2)
file(WRITE ${CMAKE_CURRENT_BINARY_DIR}/model_rising.csv "t,T\n0,1\n1,0.5\n2,0.8\n")
file(WRITE ${CMAKE_CURRENT_BINARY_DIR}/model_empty.csv "t,T\n")
weft_model_error_test(rising_table "must not increase" --law tabulated --table ${CMAKE_CURRENT_BINARY_DIR}/model_rising.csv)
weft_model_error_test(empty_table "no samples" --law tabulated --table ${CMAKE_CURRENT_BINARY_DIR}/model_empty.csv)
