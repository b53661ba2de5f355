.if later
.endif
later = 1
.else
.endif
.if 1
.else
.elseif 1
.else
.endif
.if 1
        nop
