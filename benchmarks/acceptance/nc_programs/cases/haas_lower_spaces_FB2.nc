%
o02002 (haas style lowercase, spaces inside words)
; semicolon comment line
g90 g21 g17 g54
t2 m6
g 0 x 200. y 200.
g43 h2 z 150.
f 800.
g 1 z 120.
x 260.
y 230.
x 260.5 y 230.25
x 260. y 230.
g 2 x 300. y 270. i 40. j 0.
x 340. y 230. i 0. j -40.
g 1 x 360.
g 0 z 150.
m 30
%
